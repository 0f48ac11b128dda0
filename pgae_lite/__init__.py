"""pgae_lite: PGAE (Özdemir et al., ICANN 2022) in a small, readable package.

The package, in the order the book introduces it (one concept per folder; each folder's
``__init__`` lists its modules; ``tests/test_package_map.py`` holds this list, the folders'
and the book's reference page, ``book/api.md``, to one another):

- ``world``      the world as data: the paper's words and signals, the 144 patterns, the colours (chapters 01, 02)
- ``sim``        our pybullet world: robot, scene, actions, recording (chapter 01)
- ``data``       the dataset: its type, our simulated episodes, the authors' files, a toy set (chapter 02, A1)
- ``cae``        the channel-separated convolutional autoencoder (chapter 03)
- ``model``      PGAE: its settings, layers, signals, plan head, encoders and decoders (chapter 04)
- ``train``      training PGAE: its settings, loss, loop and checkpoints (chapter 04)
- ``evaluate``   Table 1: description accuracy and joint nRMSE (chapter 04)
- ``bert``       PGAE-BERT's pretrained language encoder and the free-form language on it (chapter 05)
- ``family``     PGAE's predecessors PRAE, PVAE and PVAE-BERT(-tuned), configured per direction (PTAE is in ``model``)
- ``config``     the recipes: the profiles smoke / book / paper and Table 1's trainings
- ``runs``       the cached pipeline, side trainings, Table 1 over seeds, the results files (chapters 02-08, A1-A3)
- ``robot``      the model drives the simulated robot: closed loop, instructions, playground (chapters 07, 08)
- ``web``        the book in the reader's browser: the trained models as ONNX graphs (chapter 08)
- ``viz``        plots and animations for the chapters, by topic
- ``exercises``  check functions: a student's code against the package's, by chapter
- ``util``       plumbing: errors, the cache folder, atomic writes, argument checks
- ``__main__``   the command line: ``python -m pgae_lite --help`` (simulate, reproduce)

Layers: each folder imports only the folders below it in ``tests/test_imports.py``'s table;
``import pgae_lite.model.pgae`` needs no simulator, CAE or transformer.
"""

__version__ = "0.1.0"
