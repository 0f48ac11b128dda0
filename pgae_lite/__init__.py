"""pgae_lite: PGAE (Özdemir et al., ICANN 2022) in a small, readable package.

Modules, in the order the book introduces them:

- ``sim``         the pybullet world: robot, scene, actions, recording (chapter 01)
- ``simdata``     the 864 simulated episodes: generation, cache, split (chapter 02)
- ``cae``         the channel-separated convolutional autoencoder (chapter 03)
- ``pipeline``    simulator -> CAE -> features -> trained models, each step cached
- ``extended``    the same for a world with a new colour: record, retrain CAE and PGAE (A3)
- ``language``    vocabulary, synonyms, signals, parsing and errors (chapter 04)
- ``patterns``    the 144 patterns, their numbering and the test split (chapters 01, 02)
- ``world``       the world's colours, words and patterns as one value; ``with_colour`` (A3)
- ``data``        the dataset type and its normalisation (with whitening)
- ``original``    the authors' data loader (appendix A1)
- ``toydata``     a small synthetic dataset with the paper's structure (tests, quick demos)
- ``layers``      peephole LSTM, fused LSTM, Gated Multimodal Unit
- ``pgae``        encoders, decoders and the PGAE model
- ``signals``     the five signals: encoder inputs and decoder targets per batch
- ``config``      the profiles smoke / book / paper (data, CAE, model, training, chapters) and
                  Table 1's recipes; the only reader of the profile's environment variable
- ``train``       loss, training loop, checkpoints
- ``evaluate``    Table 1: description accuracy and joint nRMSE
- ``pretrained``  PGAE-BERT's frozen transformer language encoder (chapter 05)
- ``phrasings``, ``phrase_lexicon``, ``phrasing_bank``  generated ways of saying each instruction (chapter 05)
- ``attention_pooling``, ``tuned_layer``  the free-form variant's encoder: attention over the tokens,
                  the top layer tuned for free text (chapter 05)
- ``reproduce``   every row of Table 1 (PGAE, PGAE-BERT, PGAE-self, PGAE-opposite) over seeds
- ``closedloop``  the model drives the simulated robot, open and closed loop (chapter 07)
- ``instructions`` free-form instructions, executed both ways (chapter 07)
- ``paraphrases`` held-out free-form paraphrases of the test instructions
- ``playground``  one signal on one episode, and its ipywidgets front end (chapter 08)
- ``exercises``   check functions: a student's code against the package's, and what is wrong (by chapter)
- ``viz``         plots and animations for the chapters (by topic: scenes, vision, model, embeddings)
- ``utils``       plumbing: the cache folder, the device, atomic writes, config digests
- ``errors``      the package's errors, each a ``PGAELiteError`` (the CLI prints them)
- ``validate_api``, ``validate_playground``: argument checks of the public functions

Command line: ``python -m pgae_lite --help`` (simulate, reproduce).
"""

__version__ = "0.1.0"
