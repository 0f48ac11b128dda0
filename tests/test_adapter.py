"""pgae_lite.adapter: the language adapter is the identity when untrained, trains, and is refused without a
pretrained encoder."""
from __future__ import annotations

import pytest
import torch

from pgae_lite.adapter import LanguageAdapter
from pgae_lite.config import TRAININGS, ModelConfig


def test_untrained_adapter_passes_the_vector_through():
    f = torch.randn(4, 384)
    assert torch.equal(LanguageAdapter(384, 64)(f), f)


def test_adapter_computes_its_equation_and_learns():
    adapter = LanguageAdapter(8, 16)
    torch.nn.init.normal_(adapter.outer.weight)
    f = torch.randn(3, 8)
    by_hand = f + adapter.outer(torch.nn.functional.gelu(adapter.inner(torch.nn.functional.layer_norm(
        f, (8,), adapter.norm.weight, adapter.norm.bias))))
    torch.testing.assert_close(adapter(f), by_hand)
    adapter(f).sum().backward()
    assert all(p.grad is not None and p.grad.abs().sum() > 0 for p in adapter.parameters())


def test_adapter_needs_a_pretrained_encoder():
    with pytest.raises(ValueError, match="language_adapter works on a pretrained encoder"):
        ModelConfig(language_adapter=64)
    with pytest.raises(ValueError, match="language_adapter must be a whole number"):
        ModelConfig(language_encoder="pretrained", language_adapter=-1)
    assert ModelConfig().language_adapter == 0
    assert TRAININGS["PGAE-BERT-adapter"].model["language_adapter"] > 0
    assert "language_adapter" not in TRAININGS["PGAE-BERT"].model
