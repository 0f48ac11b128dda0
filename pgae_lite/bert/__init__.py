"""PGAE-BERT's pretrained language encoder, and the free-form language built on it (chapter 05).

- ``transformer``        the pretrained transformer, loaded offline once per process
- ``pretrained``         the frozen transformer encoder of PGAE-BERT (paper Sec. 3)
- ``attention_pooling``  the free-form variant's encoder: attention over the transformer's tokens
- ``tuned_layer``        the transformer's top layer, tuned for free text
- ``tuned_encoder``      the top layer tuned on every input, mean-pooled (PVAE-BERT's fine-tuning)
- ``word_lookup``        words never trained on, looked up in WordNet
- ``encoders``           any PGAE a ModelConfig names: the pretrained encoders passed in to the model
- ``phrase_lexicon``, ``phrasings``, ``phrasing_bank``  generated ways of saying each instruction
- ``paraphrases``        held-out free-form paraphrases of the test instructions
"""
