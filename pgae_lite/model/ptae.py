"""PTAE: PGAE's successor, a crossmodal transformer in place of the GMU (Özdemir et al., Applied
Artificial Intelligence 37(1), 2023, Sec. 3; PGAE paper, Sec. 5 names it as future work).

PGAE joins two sentence-level features, f_act and f_lang, in a gate. PTAE keeps them as
sequences and lets the words ask the frames::

    X_L = LN(ReLU(W_L [s; w_1 .. w_n])) + PE        tokens: the signal and the words, one-hot   (B, n+1, d)
    X_A = LN(ReLU(W_A [v_t; j_t])) (+ PE)           frames: every k-th step of the action         (B, S, d)
    Q, K, V = X_L W_Q, X_A W_K, X_A W_V             per head, d/heads wide
    A   = softmax(Q K^T / sqrt(d_k))                which frames each token reads                (B, heads, n+1, S)
    Y   = LN(X_L + A V W_O)                          then a feed-forward: Y' = LN(Y + W_2 ReLU(W_1 Y))
    h   = mean over the tokens of Y'                 the shared representation                    (B, d)

and h starts PGAE's own decoders (:class:`~pgae_lite.model.pgae.LanguageDecoder`,
:class:`~pgae_lite.model.pgae.ActionDecoder`), trained by PGAE's loop, signals and loss. With
the authors' main setting, the words and frames enter the transformer directly: there are no
LSTM encoders. PTAE's sizes: 1 layer, 4 heads, width 256, feed-forward 1024, dropout 0.25, and
no positions on the frames (the ``paper`` profile's PTAE).

Deviation from paper: the decoders are the book's (``ModelConfig.units`` × ``layers``, 2 × 100;
PTAE's: 2 × 128), with its time stride and plan head; the frames are those of the action
encoder's time stride, and padding frames are masked from the attention (authors: none). The
book's PTAE is 128 wide with a feed-forward of 512, no dropout, and positions on the frames
(:class:`CrossmodalConfig`, where each is measured).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import torch
from torch import nn

from pgae_lite.data.dataset import JOINT_DIM, VISION_DIM
from pgae_lite.model.config import ModelConfig, Part, flag, whole
from pgae_lite.model.language import LanguageEncoderBase
from pgae_lite.model.loss import LearnsFromSignals
from pgae_lite.model.pgae import ActionDecoder, LanguageDecoder, lstm_steps_of
from pgae_lite.model.plan import PlanHead
from pgae_lite.model.signals import SignalBatch
from pgae_lite.world.words import DEFAULT_LEXICON, VOCABULARY, LanguageError, Lexicon, word_weights


@dataclass(frozen=True)
class CrossmodalConfig(Part):
    """PTAE's crossmodal transformer (``ModelConfig.crossmodal``): one layer of ``heads`` heads and a feed-forward
    of ``feedforward`` units, ``ModelConfig.hidden`` wide. The book's PTAE is 128 wide (runs/rows.py); PTAE's
    authors: 4 heads, 256, 1024, dropout 0.25, no positions on the frames."""

    kind: ClassVar[str] = "crossmodal-transformer"
    slot: ClassVar[str] = "crossmodal"
    # Deviation from paper: the book's PTAE is 128 wide (PTAE: 256), the width ModelConfig takes when it gives
    # none; 4 heads divide it (ModelConfig's plain 50 they do not).
    hidden: ClassVar[int] = 128
    heads: int = 4
    # Deviation from paper: a feed-forward of 512 (PTAE: 1024), no dropout (PTAE: 0.25), and the frames read
    # with their positions (PTAE: none; push and pull visit the same poses in opposite orders). Each change
    # and what it did on the authors' data: benchmarks/ptae_recipe.py (results/ptae_recipe.json, A2).
    feedforward: int = 512
    dropout: float = 0.0
    frame_positions: bool = True

    def __post_init__(self):
        whole("CrossmodalConfig", "heads", self.heads, 1)
        whole("CrossmodalConfig", "feedforward", self.feedforward, 1)
        if isinstance(self.dropout, bool) or not isinstance(self.dropout, (int, float)) or not 0 <= self.dropout < 1:
            raise ValueError(f"CrossmodalConfig dropout must be a number in [0, 1); got {self.dropout!r}")
        flag("CrossmodalConfig", "frame_positions", self.frame_positions)

    def check(self, owner: ModelConfig) -> None:
        if owner.hidden % self.heads:
            raise ValueError(f"the crossmodal transformer splits its width (hidden={owner.hidden}) among "
                             f"{self.heads} heads: hidden must be a multiple of heads, e.g. "
                             f"{self.heads * max(1, round(owner.hidden / self.heads))}")
        if owner.language is not None:
            raise ValueError(f"the crossmodal transformer reads the words as tokens itself; a language encoder "
                             f"({owner.language!r}) needs the GMU (ModelConfig crossmodal=None)")


def positional_encoding(length: int, width: int) -> torch.Tensor:
    """The transformer's sinusoids (Vaswani et al. 2017), (length, width):

        PE[p, 2i] = sin(p / 10000^(2i/d)),  PE[p, 2i+1] = cos(p / 10000^(2i/d))
    """
    position = torch.arange(length, dtype=torch.float32)[:, None]                 # (length, 1)
    rate = 10000.0 ** (-torch.arange(0, width, 2, dtype=torch.float32) / width)   # (width / 2,)
    pe = torch.zeros(length, width)
    pe[:, 0::2] = torch.sin(position * rate)
    pe[:, 1::2] = torch.cos(position * rate)
    return pe


class TokenEmbedding(LanguageEncoderBase):
    """PTAE's language input: the signal and the words, each one-hot, embedded and placed.

    X_L = LN(ReLU(W_L x)) + PE, one row per token. It is a language encoder
    (:class:`~pgae_lite.model.language.LanguageEncoderBase`) that reads the dataset's words only.
    """

    def __init__(self, cfg: ModelConfig, lexicon: Lexicon = DEFAULT_LEXICON):
        super().__init__()
        self.input_dim = lexicon.input_dim                    # 28 for the paper's words
        self.signal_shift = lexicon.size - len(VOCABULARY)    # 0 for the paper's
        self.embed = nn.Linear(self.input_dim, cfg.hidden)
        self.dropout = nn.Dropout(cfg.crossmodal.dropout)
        self.norm = nn.LayerNorm(cfg.hidden)
        self.output_dim = cfg.hidden

    def encode_texts(self, texts: list[str]) -> torch.Tensor:
        """Free text: not for PTAE, which reads one-hot tokens of the dataset's words."""
        raise LanguageError("PTAE reads only the dataset's words, as tokens (pgae_lite.model.signals.make_batch); "
                            "free text needs PGAE-BERT")

    def forward(self, tokens: torch.Tensor) -> torch.Tensor:
        if self.signal_shift:                                                     # signal 23 + s -> V + s
            tokens = torch.cat([tokens[:, :1] + self.signal_shift, tokens[:, 1:]], 1)
        x = nn.functional.one_hot(tokens, self.input_dim).float()                 # (B, n+1, words + 5)
        x = self.norm(self.dropout(torch.relu(self.embed(x))))                    # LN(ReLU(W_L x))
        return x + positional_encoding(x.shape[1], x.shape[2]).to(x.device)       # + PE


class FrameEmbedding(nn.Module):
    """PTAE's action input: every k-th frame [v_t; j_t], X_A = LN(ReLU(W_A x)) (+ PE with ``frame_positions``)."""

    def __init__(self, cfg: ModelConfig):
        super().__init__()
        self.stride = cfg.time_stride
        self.positions = cfg.crossmodal.frame_positions
        self.embed = nn.Linear(VISION_DIM + JOINT_DIM, cfg.hidden)
        self.dropout = nn.Dropout(cfg.crossmodal.dropout)
        self.norm = nn.LayerNorm(cfg.hidden)

    def forward(self, inputs: torch.Tensor, lengths: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """inputs (B, T, 35), lengths (B,) -> frames (B, S, d) and which of them are real (B, S), S = ceil(T/k)."""
        k = self.stride
        frames = self.norm(self.dropout(torch.relu(self.embed(inputs[:, ::k]))))    # (B, S, d)
        if self.positions:                                                         # + PE: the frames' order
            frames = frames + positional_encoding(frames.shape[1], frames.shape[2]).to(frames.device)
        real = torch.arange(frames.shape[1], device=inputs.device) < lstm_steps_of(lengths, k)[:, None]
        return frames, real


class CrossmodalTransformer(nn.Module):
    """One layer in which the tokens (queries) attend to the frames (keys and values), then a feed-forward."""

    def __init__(self, width: int, heads: int, feedforward: int, dropout: float):
        super().__init__()
        self.heads, self.d_k = heads, width // heads
        self.query, self.key, self.value = (nn.Linear(width, width) for _ in range(3))
        self.out = nn.Linear(width, width)
        self.norm_attention, self.norm_out = nn.LayerNorm(width), nn.LayerNorm(width)
        self.feedforward = nn.Sequential(nn.Linear(width, feedforward), nn.ReLU(), nn.Dropout(dropout),
                                         nn.Linear(feedforward, width))
        self.dropout = nn.Dropout(dropout)

    def split(self, x: torch.Tensor) -> torch.Tensor:
        """(B, n, d) -> (B, heads, n, d_k)."""
        return x.view(x.shape[0], x.shape[1], self.heads, self.d_k).transpose(1, 2)

    def forward(self, tokens: torch.Tensor, frames: torch.Tensor,
                real: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """tokens (B, n, d), frames (B, S, d), real (B, S) -> Y' (B, n, d) and the attention A (B, heads, n, S)."""
        q, k, v = self.split(self.query(tokens)), self.split(self.key(frames)), self.split(self.value(frames))
        scores = q @ k.transpose(-1, -2) / math.sqrt(self.d_k)                    # Q K^T / sqrt(d_k)
        scores = scores.masked_fill(~real[:, None, None, :], float("-inf"))      # no padding frame is read
        attention = scores.softmax(-1)                                            # A, (B, heads, n, S)
        mixed = (attention @ v).transpose(1, 2).reshape(tokens.shape)            # A V, heads side by side (B, n, d)
        y = self.norm_attention(tokens + self.dropout(self.out(mixed)))           # Y = LN(X_L + A V W_O)
        return self.norm_out(y + self.dropout(self.feedforward(y))), attention   # LN(Y + W_2 ReLU(W_1 Y))


class PTAE(LearnsFromSignals, nn.Module):
    """The whole model: tokens and frames into the crossmodal transformer, h into PGAE's two decoders.

    It answers as :class:`~pgae_lite.model.pgae.PGAE` does (``encode``, ``forward``, the same
    signals and outputs), so PGAE's training loop, evaluation and closed loop run it unchanged;
    in place of the GMU's gate it gives the attention of every token over the frames.
    """

    def __init__(self, cfg: ModelConfig | None = None, lexicon: Lexicon = DEFAULT_LEXICON):
        super().__init__()
        self.cfg = cfg or ModelConfig(crossmodal=CrossmodalConfig())       # 128 wide (CrossmodalConfig.hidden)
        if self.cfg.crossmodal is None:
            raise ValueError("PTAE is the crossmodal transformer: its ModelConfig needs crossmodal=CrossmodalConfig()")
        self.lexicon = lexicon
        self.register_buffer("word_weights", word_weights(lexicon), persistent=False)   # the loss's, (words,)
        self.language_encoder = TokenEmbedding(self.cfg, lexicon)
        self.action_encoder = FrameEmbedding(self.cfg)
        part = self.cfg.crossmodal
        self.transformer = CrossmodalTransformer(self.cfg.hidden, part.heads, part.feedforward, part.dropout)
        self.language_decoder = LanguageDecoder(self.cfg, lexicon)
        self.action_decoder = ActionDecoder(self.cfg)
        self.plan_head = (PlanHead(self.cfg.hidden, self.cfg.plan_keyframes, self.cfg.units)
                          if self.cfg.plan_keyframes else None)

    def encode(self, batch: SignalBatch, language: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """Shared representation h (B, d) and the attention (B, heads, tokens, frames)."""
        if language is not None:
            raise LanguageError("PTAE reads the words as tokens, not precomputed language features")
        tokens = self.language_encoder(batch.lang_tokens)                                # (B, 5, d)
        frames, real = self.action_encoder(batch.action_input, batch.action_lengths)     # (B, S, d)
        y, attention = self.transformer(tokens, frames, real)
        said = (torch.arange(tokens.shape[1], device=y.device) < batch.lang_lengths[:, None]).float()
        h = (y * said[..., None]).sum(1) / said.sum(1, keepdim=True)                      # mean over the tokens
        return h, attention

    def forward(self, batch: SignalBatch, teacher_language: bool = False, feedback: str = "greedy",
                language: torch.Tensor | None = None) -> dict[str, torch.Tensor]:
        """``logits`` (B, 4, 23), ``joints`` (B, T-1, 5), ``h`` (B, d), ``attention``, and ``plan`` with a plan head."""
        h, attention = self.encode(batch, language)
        logits = self.language_decoder(h, batch.lang_target if teacher_language else None, feedback=feedback)
        joints = self.action_decoder(h, batch.dec_vision, batch.start_joints, steps=batch.joint_mask.sum(1))
        out = {"logits": logits, "joints": joints, "h": h, "attention": attention}
        if self.plan_head is not None:
            out["plan"] = self.plan_head(h)
        return out


__all__ = ["CrossmodalConfig", "CrossmodalTransformer", "FrameEmbedding", "PTAE", "TokenEmbedding",
           "positional_encoding"]
