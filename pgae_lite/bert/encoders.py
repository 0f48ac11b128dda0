"""Any PGAE a ModelConfig names, the pretrained language encoders included (paper Sec. 3, PGAE-BERT).

The paper's model (:class:`pgae_lite.model.pgae.PGAE`) builds its own LSTM language encoder
and imports nothing of this folder; a model with a pretrained encoder is built here, which
passes the encoder's builder in:

    model = build_pgae(ModelConfig(language_encoder="pretrained"))    # PGAE-BERT
    model = build_pgae(ModelConfig(bottleneck="crossmodal-transformer", hidden=256))   # PTAE

- ``"lstm"``: PGAE's LSTM (:class:`~pgae_lite.model.pgae.LanguageEncoder`);
- ``"pretrained"``: PGAE-BERT's frozen transformer, mean-pooled
  (:class:`~pgae_lite.bert.pretrained.PretrainedLanguageEncoder`); with ``tuned_top_layer``, its top
  layer tuned on every input, PVAE-BERT's fine-tuning (:class:`~pgae_lite.bert.tuned_encoder.TunedPretrainedEncoder`);
- ``"pretrained-attention"`` (not in the paper): the transformer read through a trained attention
  pooling, its top layer tuned for free text with ``tuned_top_layer``
  (:class:`~pgae_lite.bert.attention_pooling.AttentivePretrainedEncoder`).
"""
from __future__ import annotations

from torch import nn

from pgae_lite.bert.attention_pooling import AttentivePretrainedEncoder
from pgae_lite.bert.pretrained import PretrainedLanguageEncoder
from pgae_lite.bert.tuned_encoder import TunedPretrainedEncoder
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.pgae import PGAE, LanguageEncoder
from pgae_lite.model.ptae import PTAE
from pgae_lite.world.words import DEFAULT_LEXICON, Lexicon


def build_language_encoder(cfg: ModelConfig, lexicon: Lexicon = DEFAULT_LEXICON) -> nn.Module:
    """The language encoder ``cfg.language_encoder`` names; it has an ``output_dim``."""
    if cfg.language_encoder == "lstm":
        return LanguageEncoder(cfg, lexicon)
    if lexicon != DEFAULT_LEXICON:
        raise ValueError("the pretrained language encoder (PGAE-BERT) reads the paper's 23 words only; "
                         "use language_encoder='lstm' with a larger lexicon")
    if cfg.language_encoder == "pretrained-attention":
        return AttentivePretrainedEncoder(cfg.pretrained_model, tuned=cfg.tuned_top_layer)
    if cfg.tuned_top_layer:
        return TunedPretrainedEncoder(cfg.pretrained_model)
    return PretrainedLanguageEncoder(cfg.pretrained_model)


def build_pgae(cfg: ModelConfig | None = None, lexicon: Lexicon = DEFAULT_LEXICON) -> PGAE | PTAE:
    """PGAE with the language encoder ``cfg`` names (default: the book recipe's PGAE); with
    ``bottleneck="crossmodal-transformer"``, PTAE (:mod:`pgae_lite.model.ptae`)."""
    if cfg is not None and cfg.bottleneck == "crossmodal-transformer":
        return PTAE(cfg, lexicon)
    return PGAE(cfg, lexicon, make_language_encoder=build_language_encoder)


__all__ = ["build_language_encoder", "build_pgae"]
