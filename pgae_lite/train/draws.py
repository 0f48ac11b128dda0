"""What a training step draws at random, under the recipe (paper Sec. 4, "Training Details"; authors' code).

A model says which draws its batches take (``training_batch``, :mod:`pgae_lite.model.loss` and
:mod:`pgae_lite.model.prae`); this object makes them, from the recipe and the run's generator,
in the order the model asks::

    signals(index)       each sample's signal (TrainConfig.signal_probs, per sample or per batch;
                         under limited supervision, pgae_lite.train.supervision)
    descriptions(size)   which of the 8 equivalent descriptions each sample reads
    views(size)          whether each sample shows the opposite agent (``opposite_prob``)
    noise(action_input)  Gaussian noise on the action encoder's input (``input_noise``, ``joint_input_noise``)

The generator draws the first three, so the same seed gives the same batches; the noise comes from
torch's global generator, seeded where the run starts.
"""
from __future__ import annotations

import torch

from pgae_lite.data.dataset import JOINT_DIM
from pgae_lite.train.supervision import draw_signals
from pgae_lite.world.words import DESCRIPTIONS


def add_input_noise(action_input: torch.Tensor, std: float, joint_std: float | None = None) -> torch.Tensor:
    """``action_input`` (B, T, 30 + 5) plus Gaussian noise: ``std`` on the visual features, ``joint_std``
    on the joints (``None``: ``std`` on both)."""
    noise = torch.randn_like(action_input)
    if joint_std is None:
        return action_input + std * noise
    scale = torch.full((action_input.shape[-1],), std, device=action_input.device)
    scale[-JOINT_DIM:] = joint_std                                        # the last 5 channels are joints
    return action_input + scale * noise


class Draws:
    """The random draws of a run: ``recipe`` (a TrainConfig), its ``generator``, and which training samples are
    labelled (``labelled`` (N,) bool, under limited supervision of a share of the samples; else None)."""

    def __init__(self, recipe, generator: torch.Generator, labelled: torch.Tensor | None = None):
        self.recipe, self.generator, self.labelled = recipe, generator, labelled

    def signals(self, index: torch.Tensor) -> torch.Tensor:
        """The signals of the samples ``index`` (B,)."""
        labelled = None if self.labelled is None else self.labelled[index]
        return draw_signals(len(index), self.generator, self.recipe, labelled)

    def descriptions(self, size: int) -> torch.Tensor:
        """Which of the 8 equivalent descriptions each of ``size`` samples reads (size,)."""
        return torch.randint(DESCRIPTIONS, (size,), generator=self.generator)

    def views(self, size: int) -> torch.Tensor:
        """Whether each of ``size`` samples shows the opposite agent's view (size,) bool."""
        return torch.rand(size, generator=self.generator) < self.recipe.opposite_prob

    def noise(self, action_input: torch.Tensor) -> torch.Tensor:
        """``action_input`` with the recipe's input noise (as it is, without any)."""
        recipe = self.recipe
        if not (recipe.input_noise or recipe.joint_input_noise):
            return action_input
        return add_input_noise(action_input, recipe.input_noise, recipe.joint_input_noise)


__all__ = ["Draws", "add_input_noise"]
