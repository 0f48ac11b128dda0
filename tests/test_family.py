"""The family's parts (pgae_lite/family/): PRAE's and PVAE's binding loss."""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import torch

from pgae_lite.model.binding import binding_loss
from pgae_lite.util.errors import ArgumentError


def by_hand(z_language, z_action, margin):
    """The binding loss written out pair by pair, with plain Python numbers."""
    b = len(z_language)
    d = [[math.dist(z_action[i], z_language[j]) for j in range(b)] for i in range(b)]
    pull = sum(d[i][i] for i in range(b)) / b
    push = sum(max(0.0, margin + d[j][j] - d[i][j]) + max(0.0, margin + d[i][i] - d[i][j])
               for i, j in itertools.product(range(b), repeat=2) if i != j) / b ** 2
    return pull + push


def test_the_loss_is_its_equation():
    torch.manual_seed(0)
    z_language, z_action = torch.randn(5, 3, dtype=torch.float64), torch.randn(5, 3, dtype=torch.float64)
    for margin in (0.0, 1.0, 2.5):
        expected = by_hand(z_language.tolist(), z_action.tolist(), margin)
        assert binding_loss(z_language, z_action, margin).item() == pytest.approx(expected, rel=1e-12)


def test_bound_and_separated_codes_cost_nothing_and_a_swap_costs():
    corners = torch.eye(4, dtype=torch.float64) * 3.0            # pairs 3 * sqrt(2) > 1 apart
    assert binding_loss(corners, corners).item() == pytest.approx(0.0, abs=1e-12)
    swapped = corners[[1, 0, 2, 3]]                              # two descriptions bound to the wrong actions
    assert binding_loss(swapped, corners).item() > 1.0


def test_descending_it_pulls_pairs_together_and_pushes_others_apart():
    torch.manual_seed(1)
    z_language = torch.randn(6, 4, requires_grad=True)
    z_action = torch.randn(6, 4, requires_grad=True)
    optimiser = torch.optim.SGD([z_language, z_action], lr=0.1)
    before = binding_loss(z_language, z_action).item()
    for _ in range(300):
        optimiser.zero_grad()
        binding_loss(z_language, z_action).backward()
        optimiser.step()
    with torch.no_grad():
        d = torch.cdist(z_action, z_language)
        nearest = d.argmin(dim=1)                                # each action's nearest description
    assert binding_loss(z_language, z_action).item() < before / 5
    assert nearest.tolist() == list(range(6))                    # is its own


@pytest.mark.parametrize("shapes", [((4, 3), (4, 2)), ((4, 3), (5, 3)), ((4,), (4,))])
def test_codes_of_other_shapes_are_refused(shapes):
    with pytest.raises(ArgumentError, match="two \\(batch, dimension\\) tensors of one shape"):
        binding_loss(torch.zeros(shapes[0]), torch.zeros(shapes[1]))


def test_a_negative_margin_is_refused():
    with pytest.raises(ArgumentError, match="margin must be a number >= 0"):
        binding_loss(torch.zeros(2, 2), torch.zeros(2, 2), margin=-1.0)


# ------------------------------------------------------------------ PRAE
def prae_inputs(tensors, index, alternative=None):
    """PRAE's inputs for samples ``index``: the description's words (no signal; ``alternative``: which of
    the 8, default the first), the action, the targets."""
    from pgae_lite.model.signals import make_batch, signal_ids

    if alternative is None:
        alternative = torch.zeros(len(index), dtype=torch.long)
    from pgae_lite.model.prae import paired_inputs

    b = make_batch(tensors, index, signal_ids("repeat both", len(index)), alternative)
    return paired_inputs(b), b


def test_prae_rebuilds_each_modality_from_its_code_and_translates_only_across(toy_tensors):
    from pgae_lite.model.prae import PRAE
    from pgae_lite.model.config import ModelConfig

    model = PRAE(ModelConfig(units=16))
    x, b = prae_inputs(toy_tensors, torch.tensor([72, 0, 100, 1]))
    logits, joints, z_language, z_action = model(**x)
    assert logits.shape == (4, 4, 23) and joints.shape == b.joint_target.shape
    assert z_language.shape == z_action.shape == (4, 100)
    assert model.describe(x["inputs"], x["lengths"]).shape == (4, 4, 23)           # words only
    assert model.execute(x["tokens"], x["token_lengths"], x["vision"], x["start"]).shape == joints.shape
    torch.testing.assert_close(model.language_code(x["tokens"], x["token_lengths"]), z_language)


def test_prae_learns_both_reconstructions_and_the_binding_and_describes_across(toy_short):
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.model.prae import PRAE
    from pgae_lite.model.config import ModelConfig

    torch.manual_seed(0)
    tensors = Normaliser.fit(toy_short.split("train")).tensors(toy_short)
    model = PRAE(ModelConfig(units=16, time_stride=1))
    optimiser = torch.optim.Adam(model.parameters(), lr=3e-3)
    x, b = prae_inputs(tensors, torch.arange(24))

    def losses():
        logits, joints, z_language, z_action = model(**x)
        words = torch.nn.functional.cross_entropy(logits.transpose(1, 2), b.lang_target)
        mse = ((joints - b.joint_target) ** 2)[b.joint_mask].mean()
        return words, mse, binding_loss(z_language, z_action)

    first = [v.item() for v in losses()]
    for step in range(150):
        optimiser.zero_grad()
        total = sum(losses())
        total.backward()
        if step == 0:
            assert all(p.grad is not None for p in model.parameters())          # every part learns
        optimiser.step()
    last = [v.item() for v in losses()]
    assert all(b_ < a / 2 for a, b_ in zip(first, last)), (first, last)
    with torch.no_grad():                          # bound: the action's code reads out as its description
        described = model.describe(x["inputs"], x["lengths"]).argmax(-1)
    assert (described == b.lang_target).all(1).float().mean().item() == 1.0
    check_the_configured_cells(model, toy_short, tensors)


def check_the_configured_cells(model, data, tensors):
    """Table 1's cells of a configured model: words or joints per signal, N.A. (None) for the rest."""
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.family.configured import configured_predictions, evaluate_configured

    normaliser = Normaliser.fit(data.split("train"))
    cells, preds = evaluate_configured(model, data, normaliser, split="train")
    for signal, words in (("describe", True), ("repeat language", True), ("execute", False), ("repeat action", False)):
        assert (cells[signal]["accuracy"] is None) != words, signal
        assert (cells[signal]["nrmse"] is None) == words, signal
        assert cells[signal]["n"] == len(data.split("train"))
    assert math.isfinite(cells["execute"]["nrmse"]) and 0 <= cells["describe"]["accuracy"] <= 100
    assert all(t == "" for t in preds["execute"].text) and np.isnan(preds["describe"].joints).all()
    trained = configured_predictions(model, data.subset(np.arange(24)), normaliser, "describe")
    assert trained.correct.all()                   # the samples it trained on, described across


# ------------------------------------------------------------------ PVAE
def test_the_kl_term_is_its_equation_and_torchs():
    from pgae_lite.model.pvae import kl_divergence

    torch.manual_seed(2)
    mean, log_var = torch.randn(3, 4, dtype=torch.float64), torch.randn(3, 4, dtype=torch.float64)
    by_hand = sum(0.5 * sum(math.exp(v) - v - 1 + m * m for m, v in zip(ms, vs))
                  for ms, vs in zip(mean.tolist(), log_var.tolist())) / 3
    assert kl_divergence(mean, log_var).item() == pytest.approx(by_hand, rel=1e-12)
    q = torch.distributions.Normal(mean, (0.5 * log_var).exp())
    p = torch.distributions.Normal(torch.zeros_like(mean), torch.ones_like(mean))
    by_torch = torch.distributions.kl_divergence(q, p).sum(-1).mean().item()
    assert kl_divergence(mean, log_var).item() == pytest.approx(by_torch)


def test_a_pvae_sample_is_the_mean_with_the_authors_small_noise():
    from pgae_lite.model.pvae import PVAE, SAMPLING_STD

    torch.manual_seed(3)
    mean = torch.full((20_000, 2), 5.0)
    z = PVAE.sample(mean, torch.zeros_like(mean))                # s = 1: the noise alone, N(0, 0.1^2)
    assert (z - mean).std().item() == pytest.approx(SAMPLING_STD, rel=0.03)
    assert (z - mean).mean().abs().item() < 0.01


def test_pvae_learns_one_action_from_its_eight_descriptions(toy_short):
    """Every step draws one of the 8 equivalent descriptions of each action; the cross path then
    describes each action with one of its 8 (the one-to-many translation PRAE was not made for)."""
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.model.pvae import BINDING_WEIGHT, KL_WEIGHT, PVAE, kl_divergence
    from pgae_lite.model.config import ModelConfig

    torch.manual_seed(0)
    tensors = Normaliser.fit(toy_short.split("train")).tensors(toy_short)
    model = PVAE(ModelConfig(units=16, time_stride=1))
    optimiser = torch.optim.Adam(model.parameters(), lr=3e-3)
    index = torch.arange(24)
    for _ in range(500):
        x, b = prae_inputs(tensors, index, alternative=torch.randint(0, 8, (24,)))
        logits, joints, mean_l, mean_a, log_var_l, log_var_a = model(**x)
        loss = (torch.nn.functional.cross_entropy(logits.transpose(1, 2), b.lang_target)
                + ((joints - b.joint_target) ** 2)[b.joint_mask].mean()
                + BINDING_WEIGHT * binding_loss(mean_l, mean_a)
                + KL_WEIGHT * (kl_divergence(mean_l, log_var_l) + kl_divergence(mean_a, log_var_a)))
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
    with torch.no_grad():
        words = model.describe(x["inputs"], x["lengths"]).argmax(-1)[:, :3]             # (24, 3)
    one_of_eight = (words[:, None] == tensors["descriptions"][index]).all(-1).any(-1)   # (24,)
    assert one_of_eight.all(), one_of_eight


# ------------------------------------------------------------------ training the family
@pytest.mark.parametrize("name", ["PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned"])
def test_train_family_lowers_every_term_and_is_seeded(toy_short, name):
    from pgae_lite.family.train import train_family
    from pgae_lite.model.config import ModelConfig
    from pgae_lite.train.config import TrainConfig

    recipe = TrainConfig(epochs=6, batch_size=16, input_noise=0.0, joint_input_noise=0.0)
    cfg = ModelConfig(units=16, time_stride=1)
    first = train_family(name, toy_short, cfg, recipe, device="cpu")
    words, joints = [[h[k] for h in first.history] for k in ("words", "joints")]
    assert words[-1] < words[0] and joints[-1] < joints[0]
    assert (first.history[-1]["kl"] > 0) == name.startswith("PVAE")     # PRAE has no KL term
    again = train_family(name, toy_short, cfg, recipe, device="cpu")
    assert again.history == first.history                               # the same seed, the same numbers


def test_an_unknown_family_model_is_refused(toy_short):
    from pgae_lite.family.train import train_family

    options = "PRAE, PVAE, PVAE-BERT, PVAE-BERT-tuned"
    with pytest.raises(ValueError, match=f"unknown family model 'PTAE'; the options are: {options}"):
        train_family("PTAE", toy_short)


def test_pvae_bert_reads_the_description_through_the_frozen_pretrained_encoder(toy_short):
    """The row as its text, looked up in the encoder's table; the encoder's weights never train."""
    from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, tokens_to_text
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.model.pvae import PVAE
    from pgae_lite.family.train import train_family
    from pgae_lite.model.config import ModelConfig
    from pgae_lite.train.config import TrainConfig

    trained = train_family("PVAE-BERT", toy_short, ModelConfig(units=16, time_stride=1),
                           TrainConfig(epochs=2, batch_size=16), device="cpu")
    model = trained.model
    assert isinstance(model, PVAE) and isinstance(model.language_encoder, PretrainedLanguageEncoder)
    assert model.to_language_code.in_features == model.language_encoder.output_dim == 384
    assert not any(p.requires_grad for p in model.language_encoder.parameters())
    tensors = Normaliser.fit(toy_short.split("train")).tensors(toy_short)
    x, _ = prae_inputs(tensors, torch.tensor([0, 5]))
    assert tokens_to_text(x["tokens"][0]).startswith("repeat both ")
    expected = model.to_language_code(model.language_encoder.encode_texts([tokens_to_text(r) for r in x["tokens"]]))
    torch.testing.assert_close(model.language_code(x["tokens"], x["token_lengths"]), expected, atol=1e-5, rtol=1e-4)


def test_pvae_bert_tuned_trains_its_top_layer_and_nothing_below(toy_short):
    from pgae_lite.bert.tuned_encoder import TunedPretrainedEncoder
    from pgae_lite.family.train import train_family
    from pgae_lite.model.config import ModelConfig
    from pgae_lite.train.config import TrainConfig

    cfg, recipe = ModelConfig(units=16, time_stride=1), TrainConfig(epochs=2, batch_size=16)
    untrained = TunedPretrainedEncoder()
    trained = train_family("PVAE-BERT-tuned", toy_short, cfg, recipe, device="cpu").model
    assert isinstance(trained.language_encoder, TunedPretrainedEncoder)
    before, after = untrained.top.state_dict(), trained.language_encoder.top.state_dict()
    assert any(not torch.equal(before[k], after[k]) for k in before)     # the top layer learned
    assert not any(p.requires_grad for p in trained.language_encoder.transformer.model.parameters())


# ------------------------------------------------------------------ the chapter's models and tables
def test_family_models_trains_the_chapters_three_and_ptae_is_cached():
    from pgae_lite.model.pvae import PVAE
    from pgae_lite.model.prae import PRAE
    from pgae_lite.model.ptae import PTAE
    from pgae_lite.runs.family_models import family_models

    models = family_models("smoke", seed=0, device="cpu", progress=False, workers=1)
    assert set(models) == {"PRAE-8", "PVAE", "PTAE"}
    assert type(models["PRAE-8"].model) is PRAE and isinstance(models["PVAE"].model, PVAE)
    assert isinstance(models["PTAE"].model, PTAE)
    again = family_models("smoke", seed=0, device="cpu", progress=False, workers=1)
    assert again["PRAE-8"].history == models["PRAE-8"].history          # the cached model
    assert again["PRAE-8"].seconds == models["PRAE-8"].seconds           # loaded, not trained again
    first, second = models["PTAE"].model.state_dict(), again["PTAE"].model.state_dict()
    assert all(torch.equal(first[k], second[k]) for k in first)         # PTAE: the cached model


def test_the_family_table_marks_na_and_gives_median_and_range(tmp_path, monkeypatch):
    import json

    from pgae_lite.runs.tables import family_frame

    stats = {"median": 99.5, "min": 98.0, "max": 100.0}
    configured = {s: {"accuracy": stats if s in ("describe", "repeat language") else None,
                      "nrmse": None if s in ("describe", "repeat language") else stats}
                  for s in ("describe", "repeat language", "execute", "repeat action")}
    rows = {"PVAE": {"stats": configured, "train_seconds": [10.0, 30.0, 20.0], "parameters": 659638}}
    (tmp_path / "family-ours.json").write_text(json.dumps({"benchmark": "family", "data": {"rows": rows}}))
    monkeypatch.setenv("PGAE_LITE_RESULTS", str(tmp_path))
    frame = family_frame("ours")
    assert frame.loc["PVAE", ("describe", "words %")] == "99.50 [98.00, 100.00]"
    assert frame.loc["PVAE", ("describe", "nRMSE %")] == "N.A."
    assert frame.loc["PVAE", ("execute", "words %")] == "N.A."
    assert frame.loc["PVAE", ("", "time (s)")] == "20" and frame.loc["PVAE", ("", "parameters")] == "659,638"


def test_the_paper_profile_trains_each_family_model_as_its_authors_did():
    from pgae_lite.config import get_profile
    from pgae_lite.family.train import family_recipe

    paper, book = get_profile("paper").train, get_profile("book").train
    assert family_recipe("PRAE", book, "book", 864) is book                 # the book's recipe is everyone's
    prae = family_recipe("PRAE", paper, "paper", 864)
    assert (prae.batch_size, prae.lr, prae.epochs) == (50, 1e-3, round(20_000 * 50 / 864))
    pvae = family_recipe("PVAE", paper, "paper", 864)
    assert (pvae.batch_size, pvae.lr, pvae.epochs) == (100, 1e-4, round(15_000 * 100 / 864))
    assert (pvae.weight_decay, pvae.schedule, pvae.clip) == (0.0, "constant", None)   # Adam, as the paper's


def test_reproduce_takes_a_configured_row_writes_na_as_null_and_loads_its_model_again(original_data, tmp_path):
    import json

    import numpy as np

    from pgae_lite.runs.reproduce import reproduce

    args = dict(profile="smoke", rows="PVAE", epochs=1, out_dir=tmp_path, device="cpu", progress=False)
    reproduce(original_data, **args)
    report = json.loads((tmp_path / "results.json").read_text())
    row = report["rows"]["PVAE"]
    assert row["paper"] is None
    assert row["mean"]["describe"]["nrmse"] is None and row["mean"]["execute"]["accuracy"] is None   # N.A.
    assert isinstance(row["mean"]["describe"]["accuracy"], float) and isinstance(row["mean"]["execute"]["nrmse"], float)
    with np.load(tmp_path / "predictions.npz") as predictions:
        assert np.isnan(predictions["describe_joints"]).all()                  # no joints while describing
        assert (predictions["execute_text"] == "").all()                       # no words while executing
    saved = (tmp_path / "PVAE-seed0" / "family.pt").stat().st_mtime_ns
    again = reproduce(original_data, **args)                                    # loaded, not trained again
    assert (tmp_path / "PVAE-seed0" / "family.pt").stat().st_mtime_ns == saved
    assert again["rows"]["PVAE"]["mean"] == report["rows"]["PVAE"]["mean"]


def test_a_model_saved_by_an_older_training_code_is_refused_not_loaded(toy_short, tmp_path):
    from pgae_lite.config import get_profile
    from pgae_lite.runs.configured_unit import configured_profile, trained_configured
    from pgae_lite.util.storage import CheckpointMismatchError, load_torch, save_torch

    prof = configured_profile(get_profile("smoke"), "PRAE", 0, len(toy_short.split("train")))
    path = tmp_path / "PRAE-seed0" / "family.pt"
    trained_configured(path, "PRAE", prof, toy_short, "cpu")
    saved = load_torch(path, ("name", "training_version"), "family model")
    saved["training_version"] = 1                                               # as the first version saved it
    save_torch(saved, path)
    with pytest.raises(CheckpointMismatchError, match="trained by an older training code .version 1"):
        trained_configured(path, "PRAE", prof, toy_short, "cpu")
