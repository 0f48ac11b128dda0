"""Training PGAE (paper Sec. 3, "Loss Function", and Sec. 4, "Training Details").

- ``config``      ``TrainConfig``, the training's settings, and the recipe version saved with every checkpoint
- ``loss``        the loss (words and joints) and the optimiser's rate
- ``supervision`` limited supervision: which steps pair an action with its description (PTAE's experiment)
- ``checkpoint``  checkpoints: written atomically, read safely, checked against the data; ``load_model``
- ``loop``        the training loop, as named steps
"""
