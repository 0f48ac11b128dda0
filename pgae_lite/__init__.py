"""pgae_lite: PGAE (Özdemir et al., ICANN 2022) in a small, readable package.

Modules, in the order the book introduces them:

- ``language``  vocabulary, synonyms, signals, parsing and errors
- ``data``      the dataset type, the 144 patterns and the split, the authors' data loader
- ``toydata``   a small synthetic dataset with the paper's structure (tests, quick demos)
- ``layers``    peephole LSTM, fused LSTM, Gated Multimodal Unit
- ``pgae``      encoders, decoders and the PGAE model
- ``signals``   the five signals: encoder inputs and decoder targets per batch
- ``config``    training recipes and the profiles smoke / book / paper
- ``train``     loss, training loop, checkpoints
- ``evaluate``  Table 1: description accuracy and joint nRMSE
- ``viz``       plots for the chapters

Command line: ``python -m pgae_lite reproduce --original-data PATH``.
"""

__version__ = "0.1.0"
