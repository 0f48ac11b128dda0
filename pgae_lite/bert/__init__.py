"""PGAE-BERT's pretrained language encoder (paper Sec. 3, chapter 05), frozen or its top layer tuned.

- ``transformer``    the pretrained transformer, loaded offline once per process
- ``tuned_layer``    the transformer's top layer as a module of its own, to tune, and the page's head on it
- ``pretrained``     the frozen transformer encoder of PGAE-BERT, its table of fixed inputs, token vectors
- ``tuned_encoder``  the top layer tuned on every input, mean-pooled (PVAE-BERT's fine-tuning)
- ``config``         ``PretrainedConfig``: these encoders as a part of a recipe (``ModelConfig.language``)

Free-form language built on it (the free-form variant, phrasings, the word lookup, refusals) is
``pgae_lite.freeform``.
"""
