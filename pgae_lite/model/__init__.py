"""The paper's model: PGAE and its parts (paper Sec. 3, Fig. 3).

- ``config``   ``ModelConfig``, the architecture's settings
- ``layers``   peephole LSTM, fused LSTM, the Gated Multimodal Unit
- ``signals``  the five signals: encoder inputs and decoder targets per batch
- ``plan``     the plan head (not in the paper)
- ``pgae``     the language and action encoders and decoders, and PGAE itself
- ``ptae``     PTAE, PGAE's successor: a crossmodal transformer in place of the GMU, PGAE's decoders

The model imports only the world, the dataset type and the utilities: no simulator, no CAE, and no
pretrained transformer (a pretrained language encoder is built by ``pgae_lite.bert`` and passed in).
"""
