"""The dataset: its type, our simulated episodes, the authors' files, and a toy set (paper Sec. 4).

- ``dataset``    the dataset type and its normalisation (with whitening)
- ``simulated``  the 864 simulated episodes: generation, cache, split (chapter 02); imports the simulator
- ``original``   the authors' data loader (appendix A1)
- ``checks``     the checks the authors' files must pass before they are trusted
- ``toy``        a small synthetic dataset with the paper's structure (tests, quick demos)

Importing this folder imports none of its modules: ``pgae_lite.data.dataset`` alone needs no simulator.
"""
