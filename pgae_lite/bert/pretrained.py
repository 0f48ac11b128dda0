"""PGAE-BERT: a frozen pretrained transformer as the language encoder (paper Sec. 3).

The paper (Sec. 3, "Language Autoencoder", last paragraph; Sec. 4, "Training
details") replaces the LSTM language encoder by a pretrained BERT Base whose
weights stay frozen. The whole input, signal phrase and description, goes in
at once as text, and one sentence vector comes out for the GMU:

    "execute push red slowly"  ->  transformer  ->  mean over tokens  ->  f_lang (D,)

The fixed vocabulary allows only 869 different inputs (5 signals alone, and
3 signals x 288 descriptions), so their vectors are computed once, kept in a
table and cached on disk; training then looks rows up instead of running the
transformer. Any other text (``encode_texts``) runs through the transformer.

The transformer itself (the default all-MiniLM-L6-v2, or any Hugging Face name
or folder) is loaded by :mod:`pgae_lite.bert.transformer`.
"""
from __future__ import annotations

import itertools
import re
import time
from pathlib import Path

import torch
from torch import nn

from pgae_lite.bert.transformer import (
    DEFAULT_MODEL,
    PretrainedModelError,
    Transformer,
    load_transformer,
    model_name,
    model_source,
)
from pgae_lite.bert.tuned_layer import TopLayerHead, TunedTopLayer
from pgae_lite.model.language import LanguageEncoderBase
from pgae_lite.model.signals import EOS, LANG_IN, SIGNAL_TOKEN
from pgae_lite.util.checks import shown
from pgae_lite.util.storage import CorruptCheckpointError, cache_dir, config_digest, load_torch, save_torch
from pgae_lite.world.words import (
    INPUT_DIM,
    SIGNALS,
    SLOTS,
    SYNONYMS,
    VOCABULARY,
    WORD_INDEX,
    LanguageError,
    normalise_signal,
)

POOLINGS = ("mean", "cls")
CACHE_FORMAT = 1          # bump when the texts or the file layout change: old files are recomputed
WORDS = len(VOCABULARY)   # 23: a description word is a token below 23


def check_texts(name: str, texts) -> list[str]:
    """``texts`` as a list when it is a list or tuple of strings; else a LanguageError.

    A single string is refused: iterated, it would be read as one text per character.
    """
    if isinstance(texts, str):
        raise LanguageError(f"{name} takes a list of texts, one per sentence, e.g. "
                            f"[{texts!r:.60}]; got the string {texts!r:.60}, whose "
                            "characters would each be read as a text")
    if not isinstance(texts, (list, tuple)):
        raise LanguageError(f"{name} takes a list of texts (strings); got "
                            f"{shown(texts)}")
    for i, text in enumerate(texts):
        if not isinstance(text, str):
            raise LanguageError(f"{name} takes a list of texts (strings); got "
                                f"{text!r:.60} at position {i}")
    return list(texts)


# --------------------------------------------------------------------------- the texts
def tokens_to_text(row: torch.Tensor | list[int]) -> str:
    """One ``lang_tokens`` row (signal token 23+s, words, <EOS>...) -> the transformer's text.

    ``[24, 11, 17, 20, 0]`` -> ``"execute move up scarlet unhurriedly"``; ``[23, 0, 0, 0, 0]``
    -> ``"describe"``. Reading stops at the first <EOS>; hyphens become spaces.
    """
    words = []
    for t in torch.as_tensor(row).tolist():
        if t == EOS:
            break
        if not isinstance(t, int) or not 0 <= t < SIGNAL_TOKEN + len(SIGNALS):
            raise LanguageError(f"tokens_to_text reads token ids 0-{SIGNAL_TOKEN + len(SIGNALS) - 1} (the words, "
                                f"then the {len(SIGNALS)} signals); got {t!r:.40}")
        words.append(SIGNALS[t - SIGNAL_TOKEN] if t >= SIGNAL_TOKEN else VOCABULARY[t])
    # Deviation from paper: the authors' code fed "execute: push red slowly" (its vocabulary's
    # signal words end in a colon) and kept hyphens; the colon adds nothing, and "move up" reads
    # as English where "move-up" does not.
    return " ".join(words).replace("-", " ")


def input_text(signal: str, text: str = "") -> str:
    """Free text with its signal phrase prepended: ``input_text("execute", "push the red one")``."""
    return f"{normalise_signal(signal)} {text}".strip()


def fixed_token_rows() -> torch.Tensor:
    """Every input the vocabulary allows, as ``lang_tokens`` rows (869, 5).

    Each signal alone (5), then each signal that takes a description (execute,
    repeat both, repeat language) with each of the 288 descriptions.
    """
    rows = [[SIGNAL_TOKEN + s, EOS, EOS, EOS, EOS] for s in range(len(SIGNALS))]
    choices = [[WORD_INDEX[w] for c in slot for w in (c, SYNONYMS[c])] for slot in SLOTS]
    for s in range(len(SIGNALS)):
        if LANG_IN[s]:
            rows += [[SIGNAL_TOKEN + s, *words, EOS] for words in itertools.product(*choices)]
    return torch.tensor(rows)


def token_codes(tokens: torch.Tensor) -> torch.Tensor:
    """A number for each row, s·23³ + w1·23² + w2·23 + w3, or -1 for a row no code covers (B,)."""
    tokens = nn.functional.pad(tokens, (0, max(0, 5 - tokens.shape[1])))
    s, words = tokens[:, 0] - SIGNAL_TOKEN, tokens[:, 1:4]
    ok = (s >= 0) & (s < len(SIGNALS)) & ((words >= 0) & (words < WORDS)).all(1) & (tokens[:, 4:] == EOS).all(1)
    code = ((s * WORDS + words[:, 0]) * WORDS + words[:, 1]) * WORDS + words[:, 2]
    return torch.where(ok, code, -1)


def fixed_inputs() -> tuple[list[str], torch.Tensor]:
    """The texts of the 869 fixed inputs, and each token code's row among them (-1: none), (5·23³,)."""
    rows = fixed_token_rows()
    row_of_code = torch.full((len(SIGNALS) * WORDS ** 3,), -1)
    row_of_code[token_codes(rows)] = torch.arange(len(rows))
    return [tokens_to_text(r) for r in rows], row_of_code


def check_token_ids(tokens: torch.Tensor) -> torch.Tensor:
    """``tokens`` when every id is a word or a signal (0-27); else a LanguageError (a negative id would
    wrap round to a word, one past the table would fail deep inside)."""
    low, high = torch.aminmax(tokens) if tokens.numel() else (0, 0)
    if low < 0 or high >= INPUT_DIM:
        raise LanguageError(f"token ids must be from 0 to {INPUT_DIM - 1} ({len(VOCABULARY)} words, then "
                            f"{len(SIGNALS)} signals); got ids from {int(low)} to {int(high)}")
    return tokens


def table_rows(tokens: torch.Tensor, row_of_code: torch.Tensor) -> torch.Tensor:
    """``lang_tokens`` (B, 5) -> each row's index among the fixed inputs (B,), -1 for any other text."""
    codes = token_codes(tokens)
    return torch.where(codes >= 0, row_of_code[codes.clamp(min=0)], -1)


@torch.no_grad()
def token_vectors(tf: Transformer, texts: list[str], batch_size: int = 128, top_input: bool = False):
    """The frozen transformer's last hidden states, a batch of texts at a time, on the CPU.

    Yields ``(hidden (b, tokens, D) float32, mask (b, tokens) bool)``; ``mask`` is False on padding.
    ``top_input``: the hidden states below the last layer instead, the input of a tuned top layer
    (:mod:`pgae_lite.bert.tuned_layer`).
    """
    for i in range(0, len(texts), batch_size):
        enc = tf.tokenizer(list(texts[i:i + batch_size]), padding=True, truncation=True,
                           return_tensors="pt")
        out = tf.model(**enc, output_hidden_states=top_input)
        hidden = out.hidden_states[-2] if top_input else out.last_hidden_state
        yield hidden.float(), enc["attention_mask"].bool()


def padded_token_vectors(tf: Transformer, texts: list[str],
                         top_input: bool = False) -> tuple[torch.Tensor, torch.Tensor]:
    """Texts -> token vectors (B, T, D) and mask (B, T), padded to the longest text, on the CPU.

    ``top_input``: the top layer's input (:func:`~pgae_lite.bert.pretrained.token_vectors`), not its output."""
    pieces = list(token_vectors(tf, texts, top_input=top_input))
    longest = max((h.shape[1] for h, _ in pieces), default=1)
    states = torch.cat([nn.functional.pad(h, (0, 0, 0, longest - h.shape[1])) for h, _ in pieces])
    mask = torch.cat([nn.functional.pad(m, (0, longest - m.shape[1])) for _, m in pieces])
    return states, mask


def cached_token_vectors(tf: Transformer, texts: list[str], what: str, dtype: torch.dtype = torch.float32,
                         top_input: bool = False) -> tuple[torch.Tensor, torch.Tensor]:
    """:func:`padded_token_vectors`, kept on disk under a digest of the texts and the model."""
    key = config_digest({"texts": texts, "encoder": tf.digest, "dtype": str(dtype)})
    path = cache_dir() / "embeddings" / f"{what}-{'top-input' if top_input else 'tokens'}-{key}.pt"
    if path.exists():
        try:
            saved = load_torch(path, ("states", "mask"), what=f"{what} token cache", finite=("states",))
            if saved["states"].shape[:2] == saved["mask"].shape:
                return saved["states"], saved["mask"]
        except CorruptCheckpointError:       # damaged: computed again, never trusted
            pass
    states, mask = padded_token_vectors(tf, texts, top_input)
    states = states.to(dtype)
    save_torch({"states": states, "mask": mask}, path)               # atomic write
    return states, mask


# --------------------------------------------------------------------------- the encoder
class PretrainedLanguageEncoder(LanguageEncoderBase):
    """Frozen pretrained transformer -> one sentence vector per input, (B, output_dim).

    The transformer is held outside the module tree (a per-process cache keyed by
    model name), so it is in no ``state_dict``, no ``parameters()`` and no optimiser:
    checkpoints stay small, and the encoder is rebuilt from ``name`` when loaded.
    The table of the 869 fixed inputs is a non-persistent buffer: it follows
    ``.to(device)`` but is not saved.
    """

    reads_free_text = True

    def __init__(self, name: str | None = None, pooling: str = "mean"):
        super().__init__()
        if pooling not in POOLINGS:
            raise ValueError(f"unknown pooling {pooling!r}; the options are: {', '.join(POOLINGS)}")
        self.name, self.pooling = model_name(name), pooling
        self.output_dim = int(self.transformer.model.config.hidden_size)
        self.texts, row_of_code = fixed_inputs()
        table, self.table_source, self.table_seconds = self._load_or_compute_table()
        self.register_buffer("table", table, persistent=False)               # (869, D)
        self.register_buffer("row_of_code", row_of_code, persistent=False)   # (5·23³,)

    @property
    def transformer(self) -> Transformer:
        """The loaded tokenizer and model (loaded on first use in this process)."""
        return load_transformer(self.name)

    def export_head(self) -> nn.Module:
        """The page's head: a copy of the transformer's top layer, then the mean over the tokens."""
        if self.pooling != "mean":
            raise ValueError(f"the page pools tokens by their mean; this encoder pools by {self.pooling!r}")
        return TopLayerHead(TunedTopLayer(self.transformer))

    def encode_texts(self, texts: list[str]) -> torch.Tensor:
        """Any texts -> sentence vectors (B, output_dim), through the transformer, on the table's device.

        Put the signal phrase first, as in training: ``["execute please push the red block slowly"]``.
        ``texts`` is a list even for one text: a string alone raises a LanguageError.
        """
        texts = check_texts("encode_texts", texts)
        return self._run_transformer(texts).to(self.table.device)

    def _run_transformer(self, texts: list[str]) -> torch.Tensor:
        """Texts -> pooled last hidden states (B, output_dim), on the CPU."""
        out = [torch.zeros(0, self.output_dim)]
        for hidden, mask in token_vectors(self.transformer, texts):      # (b, tokens, D), (b, tokens)
            if self.pooling == "cls":
                out.append(hidden[:, 0])
            else:
                # Deviation from paper: the mean over real tokens only (what all-MiniLM-L6-v2
                # was trained for); the authors' code also averaged the padding.
                weight = mask[..., None].float()                            # (b, tokens, 1)
                out.append((hidden * weight).sum(1) / weight.sum(1))
        return torch.cat(out)

    def forward(self, tokens: torch.Tensor, lengths: torch.Tensor | None = None) -> torch.Tensor:
        """``lang_tokens`` (B, 5) -> (B, output_dim): a table lookup; unknown rows run the transformer.

        ``lengths`` is not needed (a row's text ends at its first <EOS>); it is accepted so
        that both language encoders are called the same way.
        """
        rows = table_rows(check_token_ids(tokens), self.row_of_code)
        out = self.table[rows.clamp(min=0)]
        missing = (rows < 0).nonzero().flatten()
        if len(missing):
            out[missing] = self.encode_texts([tokens_to_text(tokens[i]) for i in missing.tolist()])
        return out

    # ----------------------------------------------------------------------- the disk cache
    def cache_file(self) -> Path:
        """``<cache>/embeddings/<model>-<pooling>-<digest>.pt``: the file of the fixed table."""
        slug = re.sub(r"[^A-Za-z0-9._-]+", "_", self.name).strip("_")[-60:]
        return cache_dir() / "embeddings" / f"{slug}-{self.pooling}-{self.transformer.digest[:16]}.pt"

    def _cache_header(self) -> dict:
        """What a cache file must record to be trusted for this encoder."""
        return {"format": CACHE_FORMAT, "digest": self.transformer.digest, "pooling": self.pooling,
                "texts": self.texts}

    def read_cache(self, path: Path) -> tuple[torch.Tensor, float] | None:
        """The table and its compute time from a cache file; None if it is missing, damaged or another's."""
        try:       # the checks every saved file gets (util/storage.load_torch), the weights finite
            saved = load_torch(path, ("embeddings", "seconds"), what="sentence-vector cache", finite=("embeddings",))
        except CorruptCheckpointError:       # damaged or not what we wrote: recomputed, never trusted
            return None
        table = saved["embeddings"]
        if (all(saved.get(k) == v for k, v in self._cache_header().items()) and isinstance(table, torch.Tensor)
                and table.shape == (len(self.texts), self.output_dim)):
            return table.float(), float(saved["seconds"])
        return None

    def _load_or_compute_table(self) -> tuple[torch.Tensor, str, float]:
        """The fixed table from the disk cache if it is intact and matches, else computed and written."""
        path = self.cache_file()
        cached = self.read_cache(path) if path.exists() else None
        if cached is not None:
            return cached[0], "cache", cached[1]
        t0 = time.perf_counter()
        table = self._run_transformer(self.texts)
        seconds = time.perf_counter() - t0
        save_torch({**self._cache_header(), "model": self.name, "embeddings": table,
                    "seconds": seconds}, path)        # atomic: a crash never leaves half a file
        return table, "computed", seconds

    def extra_repr(self) -> str:
        return f"{self.name!r}, pooling={self.pooling!r}, output_dim={self.output_dim}, frozen"


__all__ = ["DEFAULT_MODEL", "PretrainedLanguageEncoder", "PretrainedModelError",
           "Transformer", "cached_token_vectors", "check_texts", "check_token_ids", "fixed_token_rows", "input_text",
           "padded_token_vectors",
           "fixed_inputs", "load_transformer", "model_name", "model_source", "table_rows", "token_codes",
           "token_vectors", "tokens_to_text"]
