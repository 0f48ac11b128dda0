"""pgae_lite: PGAE (Özdemir et al., ICANN 2022) in a small, readable package.

The package, in the order the book introduces it (one concept per folder; each folder's
``__init__`` lists its modules; ``tests/test_package_map.py`` holds this list, the folders'
and the book's reference page, ``book/api.md``, to one another):

- ``world``      the world as data: the paper's words and signals, the 144 patterns, the colours (chapters 01, 02)
- ``sim``        our pybullet world: robot, scene, actions, recording, and the dataset recorded in it (chapters 01, 02)
- ``data``       the dataset: its type and normalisation, the authors' files, a toy set (chapter 02, A1)
- ``cae``        the channel-separated convolutional autoencoder (chapter 03)
- ``model``      PGAE and its family: settings, layers, signals, loss, PGAE, PTAE, PRAE, PVAE (chapters 04, 09)
- ``train``      the one training loop of every model: its settings, draws, optimiser and checkpoints (chapter 04)
- ``evaluate``   measuring models: Table 1's cells, incongruent input (chapters 04, 09)
- ``bert``       PGAE-BERT's pretrained language encoder, frozen or its top layer tuned (chapter 05)
- ``freeform``   free-form language: the free-form variant's encoder, phrasings, word lookup, refusals (A4)
- ``config``     the recipes: the profiles smoke / book / paper
- ``runs``       the cached pipeline, the rows' registry, reproduce, the sweep, the result files (chapters 02-09, A1-A3)
- ``robot``      the model drives the simulated robot: closed loop, instructions, playground (chapters 07, 08)
- ``web``        the book in the reader's browser: the trained models as ONNX graphs (chapter 08)
- ``viz``        plots and animations for the chapters, by topic
- ``exercises``  check functions: a student's code against the package's, by chapter
- ``util``       plumbing: errors, the cache folder, atomic writes, argument checks
- ``__main__``   the command line: ``python -m pgae_lite --help`` (simulate, reproduce, export-web, student-edition,
                 course)
- ``course``     handing the book out as a course: the student edition, problem sets and labs, grading

Layers: each folder imports only the folders below it in ``tests/test_imports.py``'s table;
``import pgae_lite.model.pgae`` needs no simulator, CAE or transformer.
"""

__version__ = "0.1.0"
