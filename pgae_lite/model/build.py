"""Any model of the book from its settings: PGAE, PGAE-BERT, PTAE, PRAE, PVAE (paper Sec. 3; the family, Sec. 2).

Which model a :class:`~pgae_lite.model.config.ModelConfig` describes follows from its parts, never
from a name::

    binding set       PRAE (two autoencoders bound by a loss), or PVAE with binding.variational
    crossmodal set    PTAE (the crossmodal transformer in place of the GMU)
    neither           PGAE (the GMU)

and its language encoder from its ``language`` part (None: the LSTM over one-hot words; a
pretrained transformer's settings build that encoder: PGAE-BERT, PVAE-BERT, the free-form
variant). Every model answers the training loop and the evaluation the same way:
``training_data``, ``training_batch``, ``training_loss``, ``at_step`` and ``PATHS``
(:class:`pgae_lite.model.loss.LearnsFromSignals`, :class:`pgae_lite.model.prae.PRAE`).

    model = build_model(ModelConfig())                                    # PGAE
    model = build_model(ModelConfig(hidden=128, crossmodal=CrossmodalConfig()))   # PTAE
"""
from __future__ import annotations

from torch import nn

from pgae_lite.model.config import ModelConfig
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.prae import PRAE
from pgae_lite.model.ptae import PTAE
from pgae_lite.model.pvae import PVAE
from pgae_lite.world.words import DEFAULT_LEXICON, Lexicon


def build_model(cfg: ModelConfig | None = None, lexicon: Lexicon = DEFAULT_LEXICON) -> nn.Module:
    """The model ``cfg`` describes (default: the book recipe's PGAE), reading and writing ``lexicon``'s words."""
    cfg = cfg or ModelConfig()
    if cfg.binding is not None:
        return (PVAE if cfg.binding.variational else PRAE)(cfg, lexicon)
    if cfg.crossmodal is not None:
        return PTAE(cfg, lexicon)
    return PGAE(cfg, lexicon)


__all__ = ["build_model"]
