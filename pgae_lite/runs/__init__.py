"""Runs: the cached pipeline from simulator to trained models, Table 1 over seeds, the results files.

- ``pipeline``    simulator -> CAE -> features -> trained models, each step cached
- ``trainings``   trainings that are not Table 1's rows: PGAE-no-plan, the free-form variants
- ``new_colour``  the same pipeline for a world with a new colour (appendix A3)
- ``reproduce``   every row of Table 1 over seeds (``python -m pgae_lite reproduce``)
- ``table1_unit`` one training of one seed, measured on its rows: a unit of reproduce's sweep
- ``configured_unit`` such a unit for a model configured per direction (PRAE, PVAE, PVAE-BERT(-tuned)), N.A. cells
- ``sweep``       many trainings as tasks on a Dask cluster, from a laptop to a lab's cluster
- ``sweep_worker`` every worker of a sweep set up for these trainings (one thread, malloc thresholds)
- ``results``     the committed result files, read and quoted by the book and the README
- ``departures``  the book's recipe against the paper's, each departure with its measured effect
- ``opposite_scale`` chapter 06's ablation: the two-view model under three scalings
- ``family_models`` chapter 09's own PRAE, PVAE and PTAE, trained side by side
- ``family_table`` the family's result files as tables (chapter 09, A2)
- ``incongruent`` the family's experiment: which modality a model follows when action and words disagree
"""
