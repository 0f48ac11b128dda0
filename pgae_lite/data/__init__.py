"""The dataset: its type and normalisation, the authors' files, and a toy set (paper Sec. 4).

- ``dataset``     the dataset type, one for the authors' recordings and for our simulator's
- ``normaliser``  every modality to [-1, 1], the visual features whitened; how a scaling spreads the views
- ``original``    the authors' data loader (appendix A1)
- ``checks``      the checks the authors' files must pass before they are trusted
- ``toy``         a small synthetic dataset with the paper's structure (tests, quick demos)

Nothing here imports the simulator: our simulated episodes are recorded by ``pgae_lite.sim.dataset``.
"""
