"""The models: PGAE, its parts, and its family (paper Sec. 3, Fig. 3; Sec. 2; PTAE).

- ``config``    ``ModelConfig``: the settings every model reads, and the optional parts of some
- ``layers``    peephole LSTM, fused LSTM, the Gated Multimodal Unit
- ``signals``   the five signals: encoder inputs and decoder targets per batch
- ``language``  what every language encoder has: the interface the rest of the package reads
- ``plan``      the plan head (not in the paper)
- ``loss``      what PGAE learns from: its batches' draws and its loss, for the one training loop
- ``pgae``      the language and action encoders and decoders, and PGAE itself
- ``ptae``      PTAE, PGAE's successor: a crossmodal transformer in place of the GMU, PGAE's decoders
- ``binding``   the binding loss of PRAE and PVAE
- ``prae``      PRAE, PGAE's predecessor: two autoencoders bound by a loss, configured per direction
- ``pvae``      PVAE: PRAE with a variational bottleneck per modality
- ``build``     any model of the book from its settings

The model imports only the world, the dataset type and the utilities: no simulator, no CAE, and no
pretrained transformer (a pretrained language encoder is built by its settings, ``ModelConfig.language``).
"""
