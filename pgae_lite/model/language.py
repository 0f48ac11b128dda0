"""What every language encoder has: the interface the rest of the package reads (paper Sec. 3).

Paper, Sec. 3: PGAE reads its language through an LSTM over one-hot words; PGAE-BERT through a
frozen pretrained transformer. The book adds encoders of its own (the free-form variant's,
PVAE-BERT's tuned one). Whatever reads a model's language (the training loop, the playground,
the refusal rule, the page's export) asks the encoder through this interface, never by its type::

    output_dim               the size of the features f_lang it gives the bottleneck
    forward(tokens, lengths) ``lang_tokens`` rows (B, 5) -> f_lang (B, output_dim)
    reads_free_text          whether encode_texts reads any text (a pretrained transformer)
    encode_texts(texts)      free text, the signal phrase first -> f_lang (B, output_dim)
    read_as(text)            the text as the encoder reads it (a word lookup may rewrite it)
    word_lookup              what reads words training never held (a WordLookup), or None
    fixed_from_table         whether a text it was trained on is read from its frozen table rather than
                             through the transformer (the tuned variant: its fixed inputs stay frozen)
    export_head()            the module the page runs on the transformer's token vectors below its top
                             layer, (1, L, D) and a mask (1, L) -> f_lang (1, output_dim); None if none
    at_step(step, steps)     told before each training step (a tuned layer stops learning at its share)

:class:`LanguageEncoderBase` gives the defaults of an encoder that reads the dataset's words only.
"""
from __future__ import annotations

import torch
from torch import nn

from pgae_lite.world.words import LanguageError


class LanguageEncoderBase(nn.Module):
    """The interface's defaults: the dataset's words only, no lookup, nothing to export, nothing per step."""

    reads_free_text = False
    word_lookup = None
    fixed_from_table = False

    def read_as(self, text: str) -> str:
        """The text as this encoder reads it: as it is."""
        return text

    def encode_texts(self, texts: list[str]) -> torch.Tensor:
        """Free text: not for this encoder, which reads one-hot tokens of the dataset's words."""
        raise LanguageError(f"{type(self).__name__} reads only the dataset's words, as tokens "
                            "(pgae_lite.model.signals.make_batch); free text needs a pretrained encoder "
                            "(ModelConfig language=pgae_lite.bert.config.PretrainedConfig())")

    def export_head(self) -> nn.Module | None:
        """The page's head on the transformer's token vectors (see the module): None, no transformer here."""
        return None

    def at_step(self, step: int, steps: int) -> None:
        """Told before training step ``step`` of ``steps``: nothing to do."""


__all__ = ["LanguageEncoderBase"]
