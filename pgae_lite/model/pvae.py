"""PVAE: PRAE with a variational bottleneck per modality (Özdemir et al., ICDL 2021).

PGAE paper, Sec. 2: PVAE "can translate between a robot action and its multiple descriptions"
by "stochastic gradient variational Bayes-based sampling (SGVB) that randomises the hidden
representation space so that descriptions that are equivalent in meaning are represented
tightly together"; "like PRAE, PVAE employs the binding loss", and so it too must be
configured per translation direction (its cross paths, :class:`pgae_lite.model.prae.PRAE`).

Each encoder gives a mean and a log-variance, and the decoders start from a sample::

    mu = W_mu f + b_mu,   log s^2 = W_s f + b_s
    z  = mu + s * eps,    eps ~ N(0, 0.1^2)          (training; the means at inference)
    KL = 1/2 sum_k (s_k^2 - log s_k^2 - 1 + mu_k^2)  (per sample, averaged over the batch)

and the loss is the words' cross-entropy + the joints' MSE + 2 * the binding loss on the two
means + the KL term of each modality (weights from the authors' code).
"""
from __future__ import annotations

import torch
from torch import nn

from pgae_lite.model.binding import binding_loss
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.loss import pgae_loss
from pgae_lite.model.prae import PRAE, BindingConfig
from pgae_lite.model.signals import SignalBatch
from pgae_lite.world.words import DEFAULT_LEXICON, Lexicon

SAMPLING_STD = 0.1     # the authors' eps ~ N(0, 0.1^2), not N(0, 1)
BINDING_WEIGHT = 2.0   # the authors' weight of the binding loss
KL_WEIGHT = 1.0        # and of each modality's KL term


def kl_divergence(mean: torch.Tensor, log_variance: torch.Tensor) -> torch.Tensor:
    """KL(N(mu, s^2) || N(0, 1)) per sample, averaged over the batch: 1/2 sum_k (s^2 - log s^2 - 1 + mu^2)."""
    return (0.5 * (log_variance.exp() - log_variance - 1 + mean.square()).sum(-1)).mean()


class PVAE(PRAE):
    """PRAE whose codes are sampled: the means (PRAE's codes) and a log-variance head per modality."""

    def __init__(self, cfg: ModelConfig | None = None, lexicon: Lexicon = DEFAULT_LEXICON):
        cfg = cfg or ModelConfig(plan_keyframes=0, binding=BindingConfig(variational=True, all_descriptions=True))
        super().__init__(cfg, lexicon)
        shared = self.to_language_code.out_features
        self.language_log_variance = nn.Linear(self.to_language_code.in_features, shared)  # log s_L^2 = W f_L + b
        self.action_log_variance = nn.Linear(self.to_action_code.in_features, shared)      # log s_A^2 = W f_A + b

    @staticmethod
    def sample(mean: torch.Tensor, log_variance: torch.Tensor) -> torch.Tensor:
        """z = mu + s * eps with eps ~ N(0, 0.1^2): the reparameterisation trick, the authors' small noise."""
        return mean + (0.5 * log_variance).exp() * torch.randn_like(mean) * SAMPLING_STD

    def autoencode(self, batch: SignalBatch) -> tuple[torch.Tensor, ...]:
        """Training: each autoencoder rebuilds its modality from a sample of its code.

        Returns the word logits, the joints, the means mu_L, mu_A and the log-variances.
        """
        f_language = self.language_features(batch.lang_tokens, batch.lang_lengths)
        f_action = self.action_encoder(batch.action_input, batch.action_lengths)
        mean_l, mean_a = self.to_language_code(f_language), self.to_action_code(f_action)
        log_var_l, log_var_a = self.language_log_variance(f_language), self.action_log_variance(f_action)
        logits = self.language_decoder(self.sample(mean_l, log_var_l), target=batch.lang_target)
        joints = self.action_decoder(self.sample(mean_a, log_var_a), batch.dec_vision, batch.start_joints,
                                     batch.joint_mask.sum(1))
        return logits, joints, mean_l, mean_a, log_var_l, log_var_a

    def training_loss(self, batch: SignalBatch, recipe, language: torch.Tensor | None = None
                      ) -> tuple[torch.Tensor, dict[str, torch.Tensor], dict[str, torch.Tensor]]:
        """L = CE + MSE + 2 L_bind(mu_L, mu_A) + KL_L + KL_A (the authors' weights), its terms and the outputs."""
        logits, joints, mean_l, mean_a, log_var_l, log_var_a = self.autoencode(batch)
        _, words, moved = pgae_loss({"logits": logits, "joints": joints}, batch, self.word_weights)
        bind = binding_loss(mean_l, mean_a)                                   # on the means
        kl = kl_divergence(mean_l, log_var_l) + kl_divergence(mean_a, log_var_a)
        loss = words + moved + BINDING_WEIGHT * bind + KL_WEIGHT * kl
        return loss, {"words": words, "joints": moved, "binding": bind, "kl": kl}, {}


__all__ = ["BINDING_WEIGHT", "KL_WEIGHT", "PVAE", "SAMPLING_STD", "kl_divergence"]
