"""The one training loop of every model (paper Sec. 3, "Loss Function", and Sec. 4, "Training Details").

- ``config``      ``TrainConfig``, the training's settings, and the recipe version saved with every checkpoint
- ``supervision`` limited supervision: which steps pair an action with its description (PTAE's experiment)
- ``draws``       what a training step draws at random: signals, descriptions, views, input noise
- ``optimiser``   the optimiser's parameter groups and its rate over the steps
- ``checkpoint``  checkpoints: written atomically, read safely, checked against the data
- ``loop``        the training loop, as named steps: the model's batch, the model's loss, a step

The loop imports neither the pretrained encoders nor free-form language: what a training needs
beyond its recipe, its caller hands in.
"""
