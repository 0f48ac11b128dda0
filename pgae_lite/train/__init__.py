"""Training PGAE (paper Sec. 3, "Loss Function", and Sec. 4, "Training Details").

- ``config``  ``TrainConfig``, the training's settings, and the recipe version saved with every checkpoint
- ``loop``    loss, the training loop, checkpoints, ``load_model``
"""
