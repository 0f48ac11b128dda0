"""PRAE: paired recurrent autoencoders, bound by a loss (Yamada et al., RA-L 2018).

PGAE paper, Sec. 2: PRAE "consists of independent action and language networks and uses a
binding loss to align the hidden representations of the paired actions and descriptions",
and it "cannot flexibly change the direction of the translation during inference": to
describe, it runs the action encoder and the language decoder only; to execute, the language
encoder and the action decoder. Those cross paths are the only ways it translates.

Two autoencoders on this package's encoders and decoders (:mod:`pgae_lite.model.pgae`)::

    z_L = W_L f_L + b_L      f_L: the language encoder's final state over the description's words
    z_A = W_A f_A + b_A      f_A: the action encoder's final state over [v_t; j_t]
    words  <- language decoder from z_L     joints <- action decoder from z_A   (training)
    words  <- language decoder from z_A     joints <- action decoder from z_L   (the cross paths)

and the loss is the words' cross-entropy + the joints' MSE + the binding loss on (z_L, z_A)
(:func:`pgae_lite.family.binding.binding_loss`).
"""
from __future__ import annotations

from dataclasses import replace

import torch
from torch import nn

from pgae_lite.bert.encoders import build_language_encoder
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.pgae import ActionDecoder, ActionEncoder, LanguageDecoder

SHARED_DIM = 100      # the authors' shared (code) dimension


def paired_inputs(batch) -> dict:
    """PRAE's inputs from a ``"repeat both"`` :class:`~pgae_lite.model.signals.SignalBatch`: the
    description's tokens (:meth:`PRAE.language_code` reads them), the action and the decoders' inputs."""
    return dict(tokens=batch.lang_tokens, token_lengths=batch.lang_lengths,
                inputs=batch.action_input, lengths=batch.action_lengths, target_words=batch.lang_target,
                vision=batch.dec_vision, start=batch.start_joints)


class PRAE(nn.Module):
    """Two autoencoders, language and action, whose codes z_L and z_A the binding loss ties together."""

    # Deviation from paper: both autoencoders use ``cfg``'s LSTMs (the book's: 2 layers of 100
    # units); the authors' language autoencoder has 1 layer of 100 units, the action one 2 of 100.
    # ``cfg.language_encoder`` may name a pretrained encoder (PVAE-BERT's idea, pgae_lite.bert).
    def __init__(self, cfg: ModelConfig | None = None, shared_dim: int = SHARED_DIM):
        super().__init__()
        cfg = cfg or ModelConfig()
        self.shared_dim = shared_dim
        self.language_encoder = build_language_encoder(cfg)
        self.action_encoder = ActionEncoder(cfg)
        self.to_language_code = nn.Linear(self.language_encoder.output_dim, shared_dim)   # z_L = W_L f_L + b_L
        self.to_action_code = nn.Linear(cfg.state_dim, shared_dim)      # z_A = W_A f_A + b_A
        decoders = replace(cfg, hidden=shared_dim)                      # each decoder starts from a code
        self.language_decoder = LanguageDecoder(decoders)
        self.action_decoder = ActionDecoder(decoders)

    def language_code(self, tokens: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        """z_L (B, shared) of a description's ``lang_tokens`` (B, 5): the LSTM reads its words alone (PRAE
        reads no signal); a pretrained encoder reads the row as its text, "repeat both push red slowly"."""
        return self.to_language_code(self.language_features(tokens, lengths))

    def language_features(self, tokens: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        """f_L: the language encoder's output for ``lang_tokens`` (see :meth:`language_code`)."""
        if self.language_encoder.reads_free_text:
            # Deviation from paper: the pretrained encoder reads the signal's words before the description,
            # a prefix equal for every input, so that it looks the row up in its table of fixed inputs.
            return self.language_encoder(tokens, lengths)
        return self.language_encoder(tokens[:, 1:], lengths - 1)            # the words, no signal

    def action_code(self, inputs: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        """z_A (B, shared) of [v_t; j_t] (B, T, 35)."""
        return self.to_action_code(self.action_encoder(inputs, lengths))

    def forward(self, tokens, token_lengths, inputs, lengths, target_words, vision, start, steps=None):
        """Training: each autoencoder rebuilds its own modality from its own code.

        Returns the word logits (B, 4, words), the joints (B, S, 5) and the codes z_L, z_A.
        """
        z_language, z_action = self.language_code(tokens, token_lengths), self.action_code(inputs, lengths)
        logits = self.language_decoder(z_language, target=target_words)
        joints = self.action_decoder(z_action, vision, start, steps)
        return logits, joints, z_language, z_action

    def describe(self, inputs: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        """Action to language, the cross path: action encoder -> z_A -> language decoder; word logits.
        No joints: this configuration has no path to the action decoder (the paper's N.A.)."""
        return self.language_decoder(self.action_code(inputs, lengths))

    def execute(self, tokens, token_lengths, vision, start, steps=None) -> torch.Tensor:
        """Language to action, the cross path: language encoder -> z_L -> action decoder; joints.
        No words: this configuration has no path to the language decoder (no <EOS>, the paper's N.A.)."""
        return self.action_decoder(self.language_code(tokens, token_lengths), vision, start, steps)


__all__ = ["PRAE", "SHARED_DIM", "paired_inputs"]
