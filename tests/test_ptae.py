"""PTAE (pgae_lite/model/ptae.py): the crossmodal transformer against its equations and torch's attention,
what it reads and ignores, and PGAE's loop, evaluation and checkpoints running it unchanged."""
from __future__ import annotations

import math
from dataclasses import replace

import pytest
import torch

from pgae_lite.model.config import ModelConfig
from pgae_lite.model.ptae import CrossmodalConfig
from pgae_lite.model.signals import make_batch, signal_ids

SMALL = ModelConfig(units=16, hidden=32, crossmodal=CrossmodalConfig(heads=4, feedforward=64))


def ptae(cfg=SMALL, seed=0):
    from pgae_lite.model.build import build_model

    torch.manual_seed(seed)
    return build_model(cfg).eval()


def batch_of(tensors, signal, index=(0, 72, 100, 1)):
    index = torch.tensor(index)
    return make_batch(tensors, index, signal_ids(signal, len(index)), index % 8)


def test_the_recipe_builds_ptae_and_it_answers_as_pgae_does(toy_tensors):
    from pgae_lite.config import get_profile
    from pgae_lite.model.ptae import PTAE
    from pgae_lite.runs.rows import TRAININGS

    prof = TRAININGS["PTAE"].profile(get_profile("book"))
    assert prof.model.crossmodal == CrossmodalConfig() and prof.model.hidden == 128
    model = ptae()
    assert isinstance(model, PTAE)
    b = batch_of(toy_tensors, "describe")
    out = model(b)
    assert out["logits"].shape == (4, 4, 23) and out["joints"].shape == b.joint_target.shape
    assert out["h"].shape == (4, 32) and "gate" not in out
    assert out["attention"].shape == (4, 4, 5, -(-b.action_input.shape[1] // SMALL.time_stride))
    assert out["plan"].shape == (4, SMALL.plan_keyframes * 5)


def test_the_attention_is_its_equation_and_torchs(toy_tensors):
    """A = softmax(Q K^T / sqrt(d_k)) over the real frames, A V W_O equal to torch's own multi-head attention."""
    model = ptae()
    b = batch_of(toy_tensors, "repeat both")
    tokens = model.language_encoder(b.lang_tokens)
    frames, real = model.action_encoder(b.action_input, b.action_lengths)
    cmt = model.transformer
    _, attention = cmt(tokens, frames, real)
    q, k = cmt.split(cmt.query(tokens)), cmt.split(cmt.key(frames))
    by_hand = torch.softmax(q @ k.transpose(-1, -2) / math.sqrt(cmt.d_k) - 1e9 * (~real)[:, None, None].float(), -1)
    torch.testing.assert_close(attention, by_hand)
    torch_attention = torch.nn.MultiheadAttention(32, 4, batch_first=True).eval()
    with torch.no_grad():
        torch_attention.in_proj_weight.copy_(torch.cat([cmt.query.weight, cmt.key.weight, cmt.value.weight]))
        torch_attention.in_proj_bias.copy_(torch.cat([cmt.query.bias, cmt.key.bias, cmt.value.bias]))
        torch_attention.out_proj.weight.copy_(cmt.out.weight)
        torch_attention.out_proj.bias.copy_(cmt.out.bias)
        theirs, _ = torch_attention(tokens, frames, frames, key_padding_mask=~real)
        mixed = (attention @ cmt.split(cmt.value(frames))).transpose(1, 2).reshape(tokens.shape)
    torch.testing.assert_close(cmt.out(mixed), theirs, atol=1e-5, rtol=1e-4)


def test_padding_frames_are_not_read_and_the_words_order_is(toy_tensors):
    model = ptae()
    b = batch_of(toy_tensors, "execute", index=(0, 1))                    # execute: the first frame only
    h, attention = model.encode(b)
    assert (attention[..., 1:] == 0).all()                                # nothing past the real frames
    b.action_input[:, 1:] = torch.randn_like(b.action_input[:, 1:])       # so changing them changes nothing
    torch.testing.assert_close(model.encode(b)[0], h)
    b.lang_tokens[:, [1, 2]] = b.lang_tokens[:, [2, 1]]                    # two words swapped: positions matter
    assert not torch.allclose(model.encode(b)[0], h)


def test_positional_encoding_is_the_transformers_sinusoids():
    from pgae_lite.model.ptae import positional_encoding

    pe = positional_encoding(5, 8)
    assert pe[3, 2].item() == pytest.approx(math.sin(3 / 10000 ** (2 / 8)))
    assert pe[3, 5].item() == pytest.approx(math.cos(3 / 10000 ** (4 / 8)))


def test_ptae_trains_in_pgaes_loop_learns_and_loads_from_its_checkpoint(toy_short, tmp_path):
    from pgae_lite.config import get_profile
    from pgae_lite.evaluate.table1 import evaluate
    from pgae_lite.model.ptae import PTAE
    from pgae_lite.runs.pipeline import load_model
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.loop import train

    prof = TRAININGS["PTAE"].profile(get_profile("smoke", epochs=20, max_train_samples=None, batch_size=16))
    prof = replace(prof, model=replace(prof.model, hidden=32, crossmodal=replace(prof.model.crossmodal,
                                                                                  feedforward=64)))
    trained = train(toy_short, prof, out_dir=tmp_path, device="cpu", progress=False)
    losses = [r["loss"] for r in trained.history]
    assert losses[-1] < losses[0] / 2 and all("gate" in r for r in trained.history)
    loaded, normaliser, _ = load_model(tmp_path / "checkpoint.pt", "cpu", toy_short)
    assert isinstance(loaded, PTAE)
    ours, preds = evaluate(trained.model, toy_short, trained.normaliser)
    again, _ = evaluate(loaded, toy_short, normaliser)
    assert ours == again and preds["describe"].gate.shape == (36, 0)


@pytest.mark.parametrize("change, message", [
    ({"crossmodal": "attention"}, "ModelConfig crossmodal must be None or the settings of its"),
    ({"hidden": 30}, "hidden must be a multiple of heads"),
    ({"language": "pretrained"}, "ModelConfig language must be None or the settings of its"),
    ({"crossmodal": {"dropout": 1.0}}, r"CrossmodalConfig dropout must be a number in \[0, 1\)"),
    ({"crossmodal": {"heads": 0}}, "CrossmodalConfig heads must be a whole number >= 1"),
])
def test_a_wrong_transformer_setting_is_refused(change, message):
    with pytest.raises(ValueError, match=message):
        if isinstance(change.get("crossmodal"), dict):               # a setting of the part itself
            replace(SMALL, crossmodal=replace(SMALL.crossmodal, **change["crossmodal"]))
        else:
            replace(SMALL, **change)


def test_a_language_encoder_is_refused_beside_the_transformer():
    from pgae_lite.bert.config import PretrainedConfig

    with pytest.raises(ValueError, match="reads the words as tokens itself"):
        replace(SMALL, language=PretrainedConfig())


def test_ptae_reads_no_free_text(toy_tensors):
    from pgae_lite.world.words import LanguageError

    model = ptae()
    assert model.language_encoder.reads_free_text is False
    with pytest.raises(LanguageError, match="reads only the dataset's words, as tokens"):
        model.language_encoder.encode_texts(["push the red cube"])
    with pytest.raises(LanguageError, match="not precomputed language features"):
        model(batch_of(toy_tensors, "execute"), language=torch.zeros(4, 32))


def test_the_paper_profile_builds_the_authors_ptae_and_the_book_its_own():
    from pgae_lite.config import get_profile
    from pgae_lite.runs.rows import TRAININGS

    paper = TRAININGS["PTAE"].profile(get_profile("paper"))
    part = paper.model.crossmodal
    assert (paper.model.hidden, part.feedforward, part.dropout, part.frame_positions) == (256, 1024, 0.25, False)
    assert (paper.train.epochs, paper.train.batch_size, paper.train.lr) == (2500, 6, 1e-5)
    book = TRAININGS["PTAE"].profile(get_profile("book"))
    part = book.model.crossmodal
    assert (book.model.hidden, part.feedforward, part.dropout, part.frame_positions) == (128, 512, 0.0, True)
    assert TRAININGS["PGAE"].profile(get_profile("paper")).train.epochs == 6000      # PGAE keeps its own


def test_reproduce_takes_the_ptae_row_and_writes_todays_files(original_data, tmp_path):
    import json

    import numpy as np

    from pgae_lite.runs.reproduce import parse_rows, reproduce

    assert parse_rows("ptae,PGAE") == ["PTAE", "PGAE"] and "PTAE" not in parse_rows("all")   # all: Table 1's
    reproduce(original_data, profile="smoke", rows="PTAE", epochs=1, out_dir=tmp_path, device="cpu", progress=False)
    report = json.loads((tmp_path / "results.json").read_text())
    row = report["rows"]["PTAE"]
    assert row["paper"] is None and row["training"] == "PTAE"            # not a row of the paper's Table 1
    assert report["trainings"]["PTAE"]["profile"]["model"]["crossmodal"]["kind"] == "crossmodal-transformer"
    with np.load(tmp_path / "predictions.npz") as predictions:          # today's format: every cell recomputable
        assert {f"{s}_{k}" for s in ("describe", "execute", "repeat_action", "repeat_language")
                for k in ("ids", "text", "joints")} == set(predictions.files)
    assert (tmp_path / "PTAE-seed0" / "predictions-PTAE.npz").exists()
