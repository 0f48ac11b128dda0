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
(:func:`pgae_lite.model.binding.binding_loss`). It is trained on paired samples only (the signal
``repeat both``), by the one training loop (:mod:`pgae_lite.train.loop`), and measured per
configuration: each signal is one path, and a cell it has no path for is N.A. (``PRAE.PATHS``)::

    | signal          | path                                | words  | joints |
    |-----------------|-------------------------------------|--------|--------|
    | describe        | action encoder -> language decoder   | yes    | N.A.   |
    | repeat language | language encoder -> language decoder | yes    | N.A.   |
    | execute         | language encoder -> action decoder   | N.A.   | yes    |
    | repeat action   | action encoder -> action decoder     | N.A.   | yes    |
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import torch
from torch import nn

from pgae_lite.model.binding import binding_loss
from pgae_lite.model.config import ModelConfig, Part, flag
from pgae_lite.model.loss import pgae_loss
from pgae_lite.model.pgae import ActionDecoder, ActionEncoder, LanguageDecoder, build_language_encoder
from pgae_lite.model.signals import LANG_IN, REPEAT_BOTH, SIGNAL_TOKEN, SignalBatch, make_batch, signal_ids
from pgae_lite.world.words import DEFAULT_LEXICON, SIGNALS, Lexicon, word_weights

#: What each signal's configuration writes: the language decoder's words or the action decoder's joints.
PATHS = {"describe": ("words",), "repeat language": ("words",), "execute": ("joints",),
         "repeat action": ("joints",), "repeat both": ("words", "joints")}


@dataclass(frozen=True)
class BindingConfig(Part):
    """Two autoencoders bound by a loss (``ModelConfig.binding``): PRAE, or with ``variational`` PVAE
    (:mod:`pgae_lite.model.pvae`). ``all_descriptions``: each training step reads one of the 8 equivalent
    descriptions at random (PVAE's authors); else the first (PRAE's paper: one description per action)."""

    kind: ClassVar[str] = "binding"
    slot: ClassVar[str] = "binding"
    variational: bool = False
    all_descriptions: bool = False

    def __post_init__(self):
        flag("BindingConfig", "variational", self.variational)
        flag("BindingConfig", "all_descriptions", self.all_descriptions)

    def check(self, owner: ModelConfig) -> None:
        if owner.plan_keyframes:
            raise ValueError(f"PRAE and PVAE have no plan head: their ModelConfig needs plan_keyframes=0; "
                             f"got {owner.plan_keyframes}")


class PRAE(nn.Module):
    """Two autoencoders, language and action, whose codes z_L and z_A (``cfg.hidden`` each) the binding loss
    ties together."""

    PATHS = PATHS

    # Deviation from paper: both autoencoders use ``cfg``'s LSTMs (the book's: 2 layers of 100
    # units); the authors' language autoencoder has 1 layer of 100 units, the action one 2 of 100.
    # ``cfg.language`` may be a pretrained encoder (PVAE-BERT's idea, pgae_lite.bert).
    def __init__(self, cfg: ModelConfig | None = None, lexicon: Lexicon = DEFAULT_LEXICON):
        super().__init__()
        cfg = cfg or ModelConfig(hidden=100, plan_keyframes=0, binding=BindingConfig())
        if cfg.binding is None:
            raise ValueError("PRAE binds two autoencoders: its ModelConfig needs binding=BindingConfig()")
        self.cfg, self.lexicon, shared = cfg, lexicon, cfg.hidden
        self.register_buffer("word_weights", word_weights(lexicon), persistent=False)   # the loss's, (words,)
        self.language_encoder = build_language_encoder(cfg, lexicon)
        self.action_encoder = ActionEncoder(cfg)
        self.to_language_code = nn.Linear(self.language_encoder.output_dim, shared)   # z_L = W_L f_L + b_L
        self.to_action_code = nn.Linear(cfg.state_dim, shared)      # z_A = W_A f_A + b_A
        decoders = replace(cfg, hidden=shared)                      # each decoder starts from a code
        self.language_decoder = LanguageDecoder(decoders, lexicon)
        self.action_decoder = ActionDecoder(decoders)

    # ----------------------------------------------------------------------------- the two codes
    def language_features(self, tokens: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        """f_L of a description's ``lang_tokens`` (B, 5): the LSTM reads its words alone (PRAE reads no
        signal); a pretrained encoder reads the row as the text "repeat both push red slowly"."""
        if self.language_encoder.reads_free_text:
            # Deviation from paper: the pretrained encoder reads the signal's words before the description,
            # "repeat both" (its training's) for every input, so that it looks the row up in its table.
            said = torch.full_like(tokens[:, :1], SIGNAL_TOKEN + REPEAT_BOTH)
            return self.language_encoder(torch.cat([said, tokens[:, 1:]], 1), lengths)
        return self.language_encoder(tokens[:, 1:], lengths - 1)            # the words, no signal

    def language_code(self, tokens: torch.Tensor, lengths: torch.Tensor,
                      language: torch.Tensor | None = None) -> torch.Tensor:
        """z_L (B, shared) of ``lang_tokens`` (or of the features ``language`` (B, D), e.g. free text)."""
        return self.to_language_code(self.language_features(tokens, lengths) if language is None else language)

    def action_code(self, inputs: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        """z_A (B, shared) of [v_t; j_t] (B, T, 35)."""
        return self.to_action_code(self.action_encoder(inputs, lengths))

    # ----------------------------------------------------------------------------- translating
    def forward(self, batch: SignalBatch, language: torch.Tensor | None = None) -> dict[str, torch.Tensor]:
        """The configuration of the batch's signal (one for the whole batch): ``logits`` (B, 4, words) where it
        writes words, ``joints`` (B, T-1, 5) where it writes joints (see the module; ``repeat both``: both
        autoencoders, each on its own code). ``language``: features in place of the encoder's."""
        signals = batch.signal.unique()
        if len(signals) != 1:
            raise ValueError("PRAE is configured per direction: give it a batch of one signal; got "
                             f"{', '.join(SIGNALS[int(s)] for s in signals)}")
        signal = SIGNALS[int(signals[0])]
        code_l = self.language_code(batch.lang_tokens, batch.lang_lengths, language) if LANG_IN[int(signals[0])] \
            else None
        out = {}
        if "words" in self.PATHS[signal]:        # describe reads the action; repeat language, the words
            code = code_l if signal != "describe" else self.action_code(batch.action_input, batch.action_lengths)
            out["logits"] = self.language_decoder(code)
        if "joints" in self.PATHS[signal]:       # execute reads the words; repeat action, the action
            code = code_l if signal == "execute" else self.action_code(batch.action_input, batch.action_lengths)
            out["joints"] = self.action_decoder(code, batch.dec_vision, batch.start_joints, batch.joint_mask.sum(1))
        return out

    # ----------------------------------------------------------------------------- training
    def autoencode(self, batch: SignalBatch) -> tuple[torch.Tensor, ...]:
        """Training: each autoencoder rebuilds its own modality from its own code.

        Returns the word logits (B, 4, words), the joints (B, S, 5) and the codes z_L, z_A.
        """
        z_language = self.language_code(batch.lang_tokens, batch.lang_lengths)
        z_action = self.action_code(batch.action_input, batch.action_lengths)
        logits = self.language_decoder(z_language, target=batch.lang_target)
        joints = self.action_decoder(z_action, batch.dec_vision, batch.start_joints, batch.joint_mask.sum(1))
        return logits, joints, z_language, z_action

    def training_data(self, data: dict[str, torch.Tensor], patterns, recipe) -> dict[str, torch.Tensor]:
        """The training samples' tensors: nothing beside them."""
        return data

    def training_batch(self, data: dict[str, torch.Tensor], index: torch.Tensor, draws) -> SignalBatch:
        """Paired samples (``repeat both``): each reads one of its 8 descriptions (PVAE's authors) or the first
        (PRAE's one-to-one data), and its action with the input noise."""
        alternative = (draws.descriptions(len(index)) if self.cfg.binding.all_descriptions
                       else torch.zeros(len(index), dtype=torch.long))
        batch = make_batch(data, index, signal_ids("repeat both", len(index)), alternative)
        batch.action_input = draws.noise(batch.action_input)
        return batch

    def training_loss(self, batch: SignalBatch, recipe, language: torch.Tensor | None = None
                      ) -> tuple[torch.Tensor, dict[str, torch.Tensor], dict[str, torch.Tensor]]:
        """L = CE(words) + MSE(joints) + L_bind(z_L, z_A), its terms and the outputs (the recipe's α, β: not
        PRAE's, whose authors weigh the terms 1, 1, 1)."""
        logits, joints, z_language, z_action = self.autoencode(batch)
        _, words, moved = pgae_loss({"logits": logits, "joints": joints}, batch, self.word_weights)
        bind = binding_loss(z_language, z_action)
        return words + moved + bind, {"words": words, "joints": moved, "binding": bind}, {}

    def at_step(self, step: int, steps: int) -> None:
        """Called by the loop before training step ``step`` of ``steps``: the language encoder's say."""
        self.language_encoder.at_step(step, steps)


__all__ = ["BindingConfig", "PATHS", "PRAE"]
