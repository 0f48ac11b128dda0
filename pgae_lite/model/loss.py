"""What PGAE learns from: the batches its training draws and the loss (paper Sec. 3, "Loss Function"; Sec. 4).

    L = α · weighted cross-entropy(words) + β · MSE(joints)   (+ β γ L_plan with a plan head)

The word weights counter word frequency (``<BOS/EOS>`` is in every description, a colour word in
one of six); both terms are averaged over the valid steps only. A training step draws, for every
sample, a signal, one of the 8 descriptions and a view (Sec. 4; :mod:`pgae_lite.train.draws`
makes the draws), and the model learns every task from one loss.

:class:`LearnsFromSignals` is what PGAE and PTAE answer to the training loop
(:mod:`pgae_lite.train.loop`) and the evaluation (:mod:`pgae_lite.evaluate.table1`); PRAE and
PVAE answer the same questions their own way (:mod:`pgae_lite.model.prae`).
"""
from __future__ import annotations

import torch
from torch import nn

from pgae_lite.model.plan import plan_loss, plan_targets
from pgae_lite.model.signals import EXECUTE, SignalBatch, make_batch
from pgae_lite.world.words import SIGNALS


def pgae_loss(out: dict[str, torch.Tensor], batch: SignalBatch, weights: torch.Tensor,
              alpha: float = 1.0, beta: float = 1.0) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Total, language and action loss of one batch.

    language = Σ w[y] · CE(logits, y) / Σ mask  over valid words
    action   = Σ (ĵ − j)² / (5 · Σ mask)        over valid steps
    """
    ce = nn.functional.cross_entropy(out["logits"].transpose(1, 2), batch.lang_target,
                                     reduction="none")                      # (B, 4)
    m = batch.lang_mask.float()
    lang = (weights[batch.lang_target] * ce * m).sum() / m.sum()
    jm = batch.joint_mask.float()[..., None]                                # (B, T-1, 1)
    act = ((out["joints"] - batch.joint_target) ** 2 * jm).sum() / (jm.sum() * out["joints"].shape[-1])
    return alpha * lang + beta * act, lang, act


class LearnsFromSignals:
    """One model for every signal, trained on all of them at once: PGAE and PTAE (a mixin of their ``nn.Module``).

    ``PATHS``: what the model writes for each signal, words and joints for every one (the evaluation writes
    N.A. where a model has no path). Its ``language_encoder``, ``plan_head``, ``word_weights`` and
    ``forward(batch, teacher_language, feedback, language)`` are the model's own.
    """

    PATHS: dict[str, tuple[str, ...]] = {s: ("words", "joints") for s in SIGNALS}

    def training_data(self, data: dict[str, torch.Tensor], patterns, recipe) -> dict[str, torch.Tensor]:
        """The training samples' tensors and what the loss reads beside them: with a plan head (and a
        ``plan_weight``), each sample's plan target (model/plan.py)."""
        if self.plan_head is not None and recipe.plan_weight:
            patterns = torch.as_tensor(patterns, device=data["joints"].device)
            data = data | {"plan": plan_targets(data["joints"], data["lengths"], patterns, self.plan_head.keyframes)}
        return data

    def training_batch(self, data: dict[str, torch.Tensor], index: torch.Tensor, draws) -> SignalBatch:
        """The batch of samples ``index``: a signal each, a description, a view (``draws``), the input noise."""
        signal = draws.signals(index)
        alternative = draws.descriptions(len(index))
        opposite = draws.views(len(index)) & (signal != EXECUTE)       # execute shows no action to the encoder
        batch = make_batch(data, index, signal, alternative, opposite)
        batch.action_input = draws.noise(batch.action_input)      # regularises what the action encoder reads
        if "plan" in data:
            batch.plan_target = data["plan"][index.to(data["plan"].device)]
        return batch

    def training_loss(self, batch: SignalBatch, recipe, language: torch.Tensor | None = None
                      ) -> tuple[torch.Tensor, dict[str, torch.Tensor], dict[str, torch.Tensor]]:
        """The loss of one batch under ``recipe`` (a TrainConfig), its terms and the model's outputs.

        ``language`` (B, D): language features in place of the encoder's (the free-form variant's phrasings)."""
        out = self(batch, teacher_language=recipe.teacher_language,
                   feedback="greedy" if recipe.teacher_language else "soft", language=language)
        loss, lang, act = pgae_loss(out, batch, self.word_weights, recipe.language_weight, recipe.action_weight)
        if batch.plan_target is not None:      # Deviation from paper: L += β γ L_plan (model/plan.py)
            planned = plan_loss(out["plan"], batch.plan_target, batch.signal)
            loss = loss + recipe.action_weight * recipe.plan_weight * planned
        return loss, {"language_loss": lang, "action_loss": act}, out

    def at_step(self, step: int, steps: int) -> None:
        """Called by the loop before training step ``step`` of ``steps``: the language encoder's say."""
        self.language_encoder.at_step(step, steps)


__all__ = ["LearnsFromSignals", "pgae_loss"]
