"""Runs: the cached pipeline, the rows' registry, Table 1 over seeds, the sweep, the result files.

- ``rows``        the book's trainings and Table 1's and the family's rows: how each is built, trained, measured
- ``data``        simulator -> CAE -> features, each step cached; where a run's data comes from, loaded once
- ``pipeline``    any trained model of the book on that data, cached; ``load_model``
- ``table1_unit`` one training of one seed, measured on its rows: a unit of reproduce's sweep
- ``reproduce``   every row of Table 1 (and the family's) over seeds (``python -m pgae_lite reproduce``)
- ``sweep``       many trainings as tasks on a Dask cluster, from a laptop to a lab's cluster
- ``sweep_worker`` every worker of a sweep set up for these trainings (one thread, malloc thresholds)
- ``scheduler``   which Dask cluster a sweep runs on: its address checked, reached, with workers, before any data
- ``results``     the committed result files, read and quoted by the book and the README
- ``result_checks`` what a result file may hold: plain text, finite figures in their measure's range
- ``tables``      the chapters' tables of result files: the family's, the two-view ablation
- ``departures``  the book's recipe against the paper's, each departure with its measured effect
"""
