"""PVAE: PRAE with a variational bottleneck per modality (Özdemir et al., ICDL 2021).

PGAE paper, Sec. 2: PVAE "can translate between a robot action and its multiple descriptions"
by "stochastic gradient variational Bayes-based sampling (SGVB) that randomises the hidden
representation space so that descriptions that are equivalent in meaning are represented
tightly together"; "like PRAE, PVAE employs the binding loss", and so it too must be
configured per translation direction (its cross paths, :class:`pgae_lite.family.prae.PRAE`).

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

from pgae_lite.family.prae import PRAE
from pgae_lite.model.config import ModelConfig

SHARED_DIM = 50        # the authors' shared dimension
SAMPLING_STD = 0.1     # the authors' eps ~ N(0, 0.1^2), not N(0, 1)
BINDING_WEIGHT = 2.0   # the authors' weight of the binding loss
KL_WEIGHT = 1.0        # and of each modality's KL term


def kl_divergence(mean: torch.Tensor, log_variance: torch.Tensor) -> torch.Tensor:
    """KL(N(mu, s^2) || N(0, 1)) per sample, averaged over the batch: 1/2 sum_k (s^2 - log s^2 - 1 + mu^2)."""
    return (0.5 * (log_variance.exp() - log_variance - 1 + mean.square()).sum(-1)).mean()


class PVAE(PRAE):
    """PRAE whose codes are sampled: the means (PRAE's codes) and a log-variance head per modality."""

    def __init__(self, cfg: ModelConfig | None = None, shared_dim: int = SHARED_DIM):
        super().__init__(cfg, shared_dim)
        self.language_log_variance = nn.Linear(self.to_language_code.in_features, shared_dim)  # log s_L^2 = W f_L + b
        self.action_log_variance = nn.Linear(self.to_action_code.in_features, shared_dim)      # log s_A^2 = W f_A + b

    @staticmethod
    def sample(mean: torch.Tensor, log_variance: torch.Tensor) -> torch.Tensor:
        """z = mu + s * eps with eps ~ N(0, 0.1^2): the reparameterisation trick, the authors' small noise."""
        return mean + (0.5 * log_variance).exp() * torch.randn_like(mean) * SAMPLING_STD

    def forward(self, tokens, token_lengths, inputs, lengths, target_words, vision, start, steps=None):
        """Training: each autoencoder rebuilds its modality from a sample of its code.

        Returns the word logits, the joints, the means mu_L, mu_A and the log-variances.
        """
        f_language = self.language_features(tokens, token_lengths)
        f_action = self.action_encoder(inputs, lengths)
        mean_l, mean_a = self.to_language_code(f_language), self.to_action_code(f_action)
        log_var_l, log_var_a = self.language_log_variance(f_language), self.action_log_variance(f_action)
        logits = self.language_decoder(self.sample(mean_l, log_var_l), target=target_words)
        joints = self.action_decoder(self.sample(mean_a, log_var_a), vision, start, steps)
        return logits, joints, mean_l, mean_a, log_var_l, log_var_a


__all__ = ["BINDING_WEIGHT", "KL_WEIGHT", "PVAE", "SAMPLING_STD", "SHARED_DIM", "kl_divergence"]
