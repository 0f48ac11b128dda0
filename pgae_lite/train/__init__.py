"""Training PGAE (paper Sec. 4): its settings, its loss, its loop and its checkpoints.

- ``loop``   loss, the training loop, checkpoints, ``load_model``
"""
