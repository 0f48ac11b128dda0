"""A text typed for a model, read once: its description's words, or free text and its features.

Paper, Sec. 3: PGAE's LSTM reads the dataset's words only; PGAE-BERT's transformer reads any
text. A text typed in the playground is parsed once here, into one value that the rest of a
run reads from (:func:`pgae_lite.robot.playground.play`, and the closed loop it runs):

- ``words``: the description it is (``action colour speed``, synonyms kept), or None for free text,
  and ``meaning``, its parse (the canonical action, colour and speed);
- ``read``: the text as the model's language encoder reads it
  (:meth:`~pgae_lite.model.language.LanguageEncoderBase.read_as`: for the free-form
  variant, with its words never trained on looked up in WordNet; else as typed);
- :meth:`TypedText.features`: the encoder's features of the text after a signal's phrase, computed
  once per signal and kept, so each distinct input runs the transformer once.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import torch
from torch import nn

from pgae_lite.bert.pretrained import input_text
from pgae_lite.model.signals import LANG_IN
from pgae_lite.world.words import SIGNALS, LanguageError, parse_description, tokenize

#: This module's error messages as templates (``str.format``, named fields); the page fills the same ones.
MESSAGES: dict[str, str] = {
    "lstm_reads_vocabulary": "PGAE's LSTM reads only its vocabulary, in the order action colour speed "
                             "(PGAE-BERT reads free text): {error}",
    "signal_reads_no_words": "{signal} reads no words, so text can only pick the episode, and that takes "
                             "a description: {error}",
}


@dataclass
class TypedText:
    """A typed text as one model reads it (see the module docstring)."""

    typed: str
    read: str
    words: tuple[str, ...] | None
    meaning: tuple[str, str, str] | None
    encoder: nn.Module = field(repr=False)
    _features: dict[str, torch.Tensor] = field(default_factory=dict, repr=False)

    @property
    def is_free(self) -> bool:
        """Free text (read by a pretrained encoder), not one of the dataset's descriptions."""
        return self.words is None

    def features(self, signal: str) -> torch.Tensor:
        """(1, D): the encoder's features of the text after ``signal``'s phrase, computed once per signal.

        The encoder reads the typed text as ``read`` shows it (its own lookup, applied once there)."""
        if signal not in self._features:
            self._features[signal] = self.encoder.encode_texts([input_text(signal, self.typed)])
        return self._features[signal]


def read_typed(encoder: nn.Module, signal: str, text: str) -> TypedText:
    """``text`` typed for a model with this language encoder under ``signal``, parsed once.

    A description keeps its words; free text is refused with a clear LanguageError where it
    cannot be read: by PGAE's LSTM, or under a signal that reads no words.
    """
    try:
        meaning = parse_description(text)
        words = tuple(tokenize(text))
    except LanguageError as e:
        if not encoder.reads_free_text:
            raise LanguageError(MESSAGES["lstm_reads_vocabulary"].format(error=str(e))) from None
        if not LANG_IN[SIGNALS.index(signal)]:
            raise LanguageError(MESSAGES["signal_reads_no_words"].format(signal=repr(signal), error=str(e))) from None
        words = meaning = None
    return TypedText(text, encoder.read_as(text), words, meaning, encoder)


__all__ = ["TypedText", "read_typed"]
