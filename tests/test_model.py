"""pgae_lite.model.pgae: shapes, the authors' parameter count, the decoders' two modes."""
from __future__ import annotations

import pytest
import torch

from pgae_lite.config import ModelConfig
from pgae_lite.model.pgae import PGAE, count_parameters
from pgae_lite.model.signals import make_batch, signal_ids

INDEX = torch.tensor([72, 0, 100, 1])          # fast, slow, fast, slow (toy training samples)


def _batch(tensors, signal="repeat both"):
    return make_batch(tensors, INDEX, signal_ids(signal, len(INDEX)), torch.tensor([0, 1, 2, 3]))


@pytest.mark.parametrize("cell", ["lstm", "peephole"])
def test_shapes(toy_tensors, cell):
    model = PGAE(ModelConfig(units=16, cell=cell, joint_feedback="predicted"))
    out = model(_batch(toy_tensors))
    assert out["logits"].shape == (4, 4, 23)
    assert out["joints"].shape == (4, 99, 5)
    assert out["gate"].shape == out["h"].shape == (4, 50)
    assert (out["joints"].abs() <= 1).all()                       # tanh output
    assert ((out["gate"] > 0) & (out["gate"] < 1)).all()
    h, z = model.encode(_batch(toy_tensors))
    torch.testing.assert_close(h, out["h"])


def test_parameter_count_is_the_authors():
    assert count_parameters(PGAE(ModelConfig(cell="peephole", time_stride=1, plan_keyframes=0))) == 657_778
    assert ModelConfig().state_dim == 400


def test_model_config_defaults_are_the_book_recipe():
    import pgae_lite.model.pgae
    from pgae_lite.config import PROFILES

    assert ModelConfig() == PROFILES["book"].model and ModelConfig().joint_feedback == "start"
    assert PROFILES["paper"].model.joint_feedback == "predicted"      # the paper's decoder
    assert pgae_lite.model.pgae.ModelConfig is ModelConfig                   # one class, importable from both


def test_fused_parameter_count():
    """nn.LSTM has two bias vectors and no peepholes: 4·H extra − 3·H per layer."""
    per_layer = 100                                                # 4H − 3H
    assert count_parameters(PGAE(ModelConfig(time_stride=1, plan_keyframes=0))) == 657_778 + 4 * 2 * per_layer
    # time_stride 3: the decoder writes 2 x 5 more joints per step
    stride3 = 2 * 5 * (100 + 1)
    # the plan head (book recipe): h (50) -> 100 -> 10 keyframes x 5 joints
    plan = (50 + 1) * 100 + (100 + 1) * 50
    assert count_parameters(PGAE(ModelConfig())) == 657_778 + 4 * 2 * per_layer + stride3 + plan


@pytest.mark.parametrize("cell", ["lstm", "peephole"])
def test_start_and_predicted_joint_feedback_agree_at_step_0(toy_tensors, cell):
    """Both read the start joints at step 0; later only "predicted" reads its own predictions."""
    torch.manual_seed(0)
    predicted = PGAE(ModelConfig(units=16, cell=cell, joint_feedback="predicted")).eval()
    start = PGAE(ModelConfig(units=16, cell=cell, joint_feedback="start")).eval()
    start.load_state_dict(predicted.state_dict())
    b = _batch(toy_tensors)
    with torch.no_grad():
        free, fused = predicted(b), start(b, teacher_language=True)
    torch.testing.assert_close(fused["logits"][:, 0], free["logits"][:, 0])
    torch.testing.assert_close(fused["joints"][:, 0], free["joints"][:, 0])
    torch.testing.assert_close(fused["h"], free["h"])
    assert not torch.allclose(fused["joints"][:, 1:], free["joints"][:, 1:])


@pytest.mark.parametrize("feedback", ["start", "predicted"])
def test_action_decoder_never_reads_the_target_joints(toy_tensors, feedback):
    model = PGAE(ModelConfig(units=16, joint_feedback=feedback)).eval()
    b = _batch(toy_tensors)
    changed = _batch(toy_tensors)
    changed.joint_target = changed.joint_target + 0.5
    with torch.no_grad():
        assert torch.equal(model(b)["joints"], model(changed)["joints"])


@pytest.mark.parametrize("cell", ["lstm", "peephole"])
def test_language_decoder_modes(toy_tensors, cell):
    model = PGAE(ModelConfig(units=16, cell=cell, joint_feedback="predicted")).eval()
    b = _batch(toy_tensors)
    with torch.no_grad():
        h, _ = model.encode(b)
        greedy = model.language_decoder(h)
        soft = model.language_decoder(h, feedback="soft")
        # Greedy free-running = teacher forcing on its own argmax words.
        forced_own = model.language_decoder(h, target=greedy.argmax(-1))
    torch.testing.assert_close(forced_own, greedy, atol=1e-5, rtol=1e-5)
    torch.testing.assert_close(soft[:, 0], greedy[:, 0])
    assert greedy.shape == soft.shape == (4, 4, 23)


def test_gradients_reach_every_module(toy_tensors):
    model = PGAE(ModelConfig(units=16, joint_feedback="predicted"))
    out = model(_batch(toy_tensors), teacher_language=True)
    (out["logits"].sum() + out["joints"].sum() + out["plan"].sum()).backward()
    missing = [n for n, p in model.named_parameters() if p.grad is None or p.grad.abs().sum() == 0]
    assert not missing


@pytest.mark.parametrize("cell", ["lstm", "peephole"])
def test_free_running_decoder_stops_each_sample_after_its_length(toy_tensors, cell):
    """Skipping finished samples changes nothing on valid steps, and leaves zeros past them."""
    model = PGAE(ModelConfig(units=16, cell=cell, joint_feedback="predicted")).eval()
    b = _batch(toy_tensors)
    steps = b.joint_mask.sum(1)
    assert len(set(steps.tolist())) == 2                            # a mix of fast and slow samples
    with torch.no_grad():
        h, _ = model.encode(b)
        full = model.action_decoder(h, b.dec_vision, b.start_joints)
        short = model.action_decoder(h, b.dec_vision, b.start_joints, steps=steps)
    mask = b.joint_mask[..., None].expand_as(full)
    torch.testing.assert_close(short[mask], full[mask])
    assert (short[~mask] == 0).all()


@pytest.mark.parametrize("stride", [2, 3])
@pytest.mark.parametrize("feedback", ["start", "predicted"])
def test_a_strided_model_reads_every_kth_frame_and_writes_every_pose(toy_tensors, stride, feedback):
    model = PGAE(ModelConfig(units=16, time_stride=stride, joint_feedback=feedback)).eval()
    b, changed = _batch(toy_tensors), _batch(toy_tensors)
    unread = torch.ones(changed.dec_vision.shape[1], dtype=torch.bool)
    unread[::stride] = False                                          # the frames the decoder reads
    changed.dec_vision[:, unread] += 0.5
    with torch.no_grad():
        out = model(b)
        assert torch.equal(out["joints"], model(changed)["joints"])
        changed.dec_vision[:, stride] += 0.5                          # a frame it reads: the poses after it change
        moved = (model(changed)["joints"] != out["joints"]).any(2).any(0)
    assert out["joints"].shape == b.joint_target.shape
    assert not moved[:stride].any() and moved[stride:2 * stride].all()
    # The encoder reads every stride-th step only.
    b2 = _batch(toy_tensors)
    b2.action_input[:, 1::stride] += 0.5
    with torch.no_grad():
        assert torch.equal(model(b2)["h"], out["h"])
        b2.action_input[:, stride] += 0.5
        assert not torch.equal(model(b2)["h"][b2.action_lengths > stride], out["h"][b2.action_lengths > stride])


def test_time_stride_must_be_a_positive_whole_number():
    for bad in (0, -1, 1.5):
        with pytest.raises(ValueError, match="time_stride"):
            ModelConfig(time_stride=bad)
