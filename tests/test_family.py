"""The family (pgae_lite/model/prae.py, pvae.py, binding.py): PRAE's and PVAE's binding loss, their paths,
their training by the one loop (checkpoints, resume, recipes) and the one evaluation's N.A. cells."""
from __future__ import annotations

import itertools
import math
from dataclasses import replace

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
def small(name: str = "PRAE", **model):
    """The model config of a family training (runs/rows.py), smaller: 16 units, one LSTM step per time step."""
    from pgae_lite.config import ModelConfig
    from pgae_lite.runs.rows import TRAININGS

    return replace(ModelConfig(units=16, time_stride=1), **{**TRAININGS[name].model, **model})


def paired_batch(tensors, index, alternative=None, signal="repeat both"):
    """A batch of samples ``index`` with one signal (``alternative``: which of the 8 descriptions, default the
    first)."""
    from pgae_lite.model.signals import make_batch, signal_ids

    if alternative is None:
        alternative = torch.zeros(len(index), dtype=torch.long)
    return make_batch(tensors, index, signal_ids(signal, len(index)), alternative)


def test_prae_rebuilds_each_modality_from_its_code_and_translates_only_across(toy_tensors):
    from pgae_lite.model.prae import PRAE

    model = PRAE(small())
    index = torch.tensor([72, 0, 100, 1])
    b = paired_batch(toy_tensors, index)
    logits, joints, z_language, z_action = model.autoencode(b)
    assert logits.shape == (4, 4, 23) and joints.shape == b.joint_target.shape
    assert z_language.shape == z_action.shape == (4, 100)                     # the codes: cfg.hidden
    described = model(paired_batch(toy_tensors, index, signal="describe"))
    assert set(described) == {"logits"} and described["logits"].shape == (4, 4, 23)      # words only
    executed = model(paired_batch(toy_tensors, index, signal="execute"))
    assert set(executed) == {"joints"} and executed["joints"].shape == joints.shape       # joints only
    assert set(model(b)) == {"logits", "joints"}                               # repeat both: both autoencoders
    torch.testing.assert_close(model.language_code(b.lang_tokens, b.lang_lengths), z_language)
    torch.testing.assert_close(model.action_code(b.action_input, b.action_lengths), z_action)
    assert PRAE(small(hidden=12)).to_language_code.out_features == 12          # SHARED_DIM is cfg.hidden


def test_prae_is_configured_per_direction_and_needs_its_binding(toy_tensors):
    from pgae_lite.config import ModelConfig
    from pgae_lite.model.prae import PRAE, BindingConfig
    from pgae_lite.model.signals import make_batch, signal_ids

    model = PRAE(small())
    mixed = make_batch(toy_tensors, torch.tensor([0, 1]), signal_ids(["describe", "execute"]), torch.tensor([0, 0]))
    with pytest.raises(ValueError, match="give it a batch of one signal; got describe, execute"):
        model(mixed)
    with pytest.raises(ValueError, match="PRAE binds two autoencoders: its ModelConfig needs binding=BindingConfig"):
        PRAE(ModelConfig(units=16, plan_keyframes=0))
    default = PRAE()
    assert default.cfg.binding == BindingConfig() and default.cfg.hidden == 100 and default.cfg.plan_keyframes == 0


def test_build_model_builds_the_model_its_parts_describe():
    """Which model a config builds follows from its parts, never from a name."""
    from pgae_lite.config import get_profile
    from pgae_lite.model.build import build_model
    from pgae_lite.model.pgae import PGAE
    from pgae_lite.model.prae import PRAE
    from pgae_lite.model.ptae import PTAE
    from pgae_lite.model.pvae import PVAE
    from pgae_lite.runs.rows import TRAININGS

    smoke = get_profile("smoke")
    built = {name: type(build_model(TRAININGS[name].profile(smoke).model)) for name in ("PGAE", "PRAE", "PRAE-8",
                                                                                         "PVAE", "PTAE")}
    assert built == {"PGAE": PGAE, "PRAE": PRAE, "PRAE-8": PRAE, "PVAE": PVAE, "PTAE": PTAE}
    assert PRAE.PATHS["describe"] == ("words",) and PRAE.PATHS["execute"] == ("joints",)
    assert all(paths == ("words", "joints") for paths in PGAE.PATHS.values())


def test_prae_learns_both_reconstructions_and_the_binding_and_describes_across(toy_short):
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.model.prae import PRAE

    torch.manual_seed(0)
    tensors = Normaliser.fit(toy_short.split("train")).tensors(toy_short)
    model = PRAE(small())
    optimiser = torch.optim.Adam(model.parameters(), lr=3e-3)
    index = torch.arange(24)
    b = paired_batch(tensors, index)

    def losses():
        logits, joints, z_language, z_action = model.autoencode(b)
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
    model.eval()
    with torch.no_grad():                          # bound: the action's code reads out as its description
        described = model(paired_batch(tensors, index, signal="describe"))["logits"].argmax(-1)
    assert (described == b.lang_target).all(1).float().mean().item() == 1.0
    check_the_configured_cells(model, toy_short)


def check_the_configured_cells(model, data):
    """Table 1's cells of a configured model: words or joints per signal, N.A. (None) for the rest."""
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.evaluate.table1 import evaluate, predict

    normaliser = Normaliser.fit(data.split("train"))
    cells, preds = evaluate(model, data, normaliser, split="train")
    for signal, words in (("describe", True), ("repeat language", True), ("execute", False), ("repeat action", False)):
        assert (cells[signal]["accuracy"] is None) != words, signal
        assert (cells[signal]["nrmse"] is None) == words, signal
        assert cells[signal]["n"] == len(data.split("train"))
    assert math.isfinite(cells["execute"]["nrmse"]) and 0 <= cells["describe"]["accuracy"] <= 100
    assert all(t == "" for t in preds["execute"].text) and np.isnan(preds["describe"].joints).all()
    trained = predict(model, data.subset(np.arange(24)), normaliser, "describe")
    assert trained.correct.all()                   # the samples it trained on, described across


def test_the_evaluation_writes_na_exactly_where_a_model_has_no_path(toy_short):
    """One evaluation for every model: a cell is None exactly where the model's PATHS has no output for it."""
    from pgae_lite.config import ModelConfig
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.evaluate.table1 import evaluate, format_table
    from pgae_lite.model.pgae import PGAE
    from pgae_lite.model.prae import PRAE
    from pgae_lite.model.ptae import PTAE, CrossmodalConfig
    from pgae_lite.model.pvae import PVAE
    from pgae_lite.world.words import TEST_SIGNALS

    normaliser = Normaliser.fit(toy_short.split("train"))
    models = {"PGAE": PGAE(ModelConfig(units=8)), "PTAE": PTAE(ModelConfig(units=8, hidden=16,
                                                                          crossmodal=CrossmodalConfig())),
              "PRAE": PRAE(small()), "PVAE": PVAE(small("PVAE"))}
    results = {}
    for name, model in models.items():
        cells, preds = evaluate(model, toy_short, normaliser)
        results[name] = cells
        for signal in TEST_SIGNALS:
            writes = model.PATHS[signal]
            assert (cells[signal]["accuracy"] is None) == ("words" not in writes), (name, signal)
            assert (cells[signal]["nrmse"] is None) == ("joints" not in writes), (name, signal)
            assert (cells[signal]["nrmse_padded"] is None) == ("joints" not in writes), (name, signal)
            assert cells[signal]["n"] == len(toy_short.split("test"))
            assert np.isnan(preds[signal].joints).all() == ("joints" not in writes), (name, signal)
    for name in ("PGAE", "PTAE"):                                      # every cell
        assert all(v is not None for c in results[name].values() for v in c.values()), name
    for name in ("PRAE", "PVAE"):
        assert results[name]["describe"]["accuracy"] is not None and results[name]["describe"]["nrmse"] is None
        assert results[name]["execute"]["nrmse"] is not None and results[name]["execute"]["accuracy"] is None
    table = format_table(results)
    assert table.count("N.A.") == 8                                   # PRAE's and PVAE's: 2 rows x 2 x 2 tables


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

    torch.manual_seed(0)
    tensors = Normaliser.fit(toy_short.split("train")).tensors(toy_short)
    model = PVAE(small("PVAE"))
    optimiser = torch.optim.Adam(model.parameters(), lr=3e-3)
    index = torch.arange(24)
    for _ in range(500):
        b = paired_batch(tensors, index, alternative=torch.randint(0, 8, (24,)))
        logits, joints, mean_l, mean_a, log_var_l, log_var_a = model.autoencode(b)
        loss = (torch.nn.functional.cross_entropy(logits.transpose(1, 2), b.lang_target)
                + ((joints - b.joint_target) ** 2)[b.joint_mask].mean()
                + BINDING_WEIGHT * binding_loss(mean_l, mean_a)
                + KL_WEIGHT * (kl_divergence(mean_l, log_var_l) + kl_divergence(mean_a, log_var_a)))
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
    model.eval()
    with torch.no_grad():
        words = model(paired_batch(tensors, index, signal="describe"))["logits"].argmax(-1)[:, :3]   # (24, 3)
    one_of_eight = (words[:, None] == tensors["descriptions"][index]).all(-1).any(-1)   # (24,)
    assert one_of_eight.all(), one_of_eight


# ------------------------------------------------------------------ training the family by the one loop
def family_profile(name: str, epochs: int = 6, **train):
    """A small recipe of the family training ``name`` (runs/rows.py), for the one training loop."""
    from pgae_lite.config import Profile, TrainConfig
    from pgae_lite.runs.rows import TRAININGS

    base = Profile("tiny", small(), TrainConfig(epochs=epochs, batch_size=16, input_noise=0.0, joint_input_noise=0.0,
                                                checkpoint_every=1, **train))
    return TRAININGS[name].profile(base)


@pytest.mark.parametrize("name", ["PRAE", "PVAE", "PVAE-BERT", "PVAE-BERT-tuned"])
def test_the_loop_trains_the_family_lowers_every_term_and_is_seeded(toy_short, name):
    from pgae_lite.train.loop import train

    prof = family_profile(name, epochs=12)    # 12: PVAE's words fall slowly at first (its codes are sampled)
    first = train(toy_short, prof, device="cpu", progress=False, name=name)
    words, joints = [[h[k] for h in first.history] for k in ("words", "joints")]
    assert words[-1] < words[0] and joints[-1] < joints[0]
    assert set(first.history[-1]) == {"epoch", "loss", "words", "joints", "binding", "lr", "gate"} | (
        {"kl"} if name.startswith("PVAE") else set())                  # PRAE has no KL term
    assert first.history[-1]["gate"] == {}                             # no GMU
    if name.startswith("PVAE"):
        assert first.history[-1]["kl"] > 0
    again = train(toy_short, prof, device="cpu", progress=False, name=name)
    assert again.history == first.history                               # the same seed, the same numbers


@pytest.mark.parametrize("name", ["PRAE", "PVAE"])
def test_the_family_gets_checkpoints_and_resumes_bit_for_bit(toy_short, tmp_path, interrupt_training, name):
    """The smoke recipe of PRAE and PVAE through the one loop: a run stopped after its 2nd of 3 epochs (the 3rd
    unsaved) and resumed gives the weights of the run trained at once, bit for bit."""
    from pgae_lite.config import get_profile
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.checkpoint import CHECKPOINT, load_checkpoint
    from pgae_lite.train.loop import train

    prof = TRAININGS[name].profile(get_profile("smoke", epochs=3, max_train_samples=48, batch_size=16))
    assert prof.train.checkpoint_every == 1 and prof.model.binding is not None
    whole = train(toy_short, prof, out_dir=tmp_path / "whole", device="cpu", progress=False)
    assert load_checkpoint(tmp_path / "whole" / CHECKPOINT)["epoch"] == 3
    interrupt_training(toy_short, prof, tmp_path / "cut", epoch=3)
    saved = load_checkpoint(tmp_path / "cut" / CHECKPOINT)
    assert saved["epoch"] == 2 and saved["profile"] == prof.to_dict()
    epochs_run = []
    resumed = train(toy_short, prof, out_dir=tmp_path / "cut", device="cpu", progress=False,
                    callback=lambda epoch, *_: epochs_run.append(epoch))
    assert epochs_run == [3]                                           # only the unsaved epoch again
    assert resumed.history == whole.history
    first, second = whole.model.state_dict(), resumed.model.state_dict()
    assert first.keys() == second.keys() and all(torch.equal(first[k], second[k]) for k in first)
    other = train(toy_short, TRAININGS[name].profile(get_profile("smoke", epochs=3, max_train_samples=48,
                                                                 batch_size=16, seed=1)), device="cpu", progress=False)
    assert other.history != whole.history                              # a test that can fail: the seed counts


def test_build_model_refuses_a_binding_with_a_plan_head():
    from pgae_lite.config import ModelConfig
    from pgae_lite.model.prae import BindingConfig

    with pytest.raises(ValueError, match="PRAE and PVAE have no plan head"):
        ModelConfig(binding=BindingConfig())                          # plan_keyframes=10, the book's default


def test_pvae_bert_reads_the_description_through_the_frozen_pretrained_encoder(toy_short):
    """The row as its text, looked up in the encoder's table; the encoder's weights never train."""
    from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, tokens_to_text
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.model.pvae import PVAE
    from pgae_lite.train.loop import train

    trained = train(toy_short, family_profile("PVAE-BERT", epochs=2), device="cpu", progress=False)
    model = trained.model
    assert isinstance(model, PVAE) and isinstance(model.language_encoder, PretrainedLanguageEncoder)
    assert model.to_language_code.in_features == model.language_encoder.output_dim == 384
    assert not any(p.requires_grad for p in model.language_encoder.parameters())
    tensors = Normaliser.fit(toy_short.split("train")).tensors(toy_short)
    b = paired_batch(tensors, torch.tensor([0, 5]))
    assert tokens_to_text(b.lang_tokens[0]).startswith("repeat both ")
    expected = model.to_language_code(model.language_encoder.encode_texts([tokens_to_text(r) for r in b.lang_tokens]))
    torch.testing.assert_close(model.language_code(b.lang_tokens, b.lang_lengths), expected, atol=1e-5, rtol=1e-4)


def test_pvae_bert_tuned_trains_its_top_layer_and_nothing_below(toy_short):
    from pgae_lite.bert.tuned_encoder import TunedPretrainedEncoder
    from pgae_lite.train.loop import train

    untrained = TunedPretrainedEncoder()
    trained = train(toy_short, family_profile("PVAE-BERT-tuned", epochs=2), device="cpu", progress=False).model
    assert isinstance(trained.language_encoder, TunedPretrainedEncoder)
    before, after = untrained.top.state_dict(), trained.language_encoder.top.state_dict()
    assert any(not torch.equal(before[k], after[k]) for k in before)     # the top layer learned
    assert not any(p.requires_grad for p in trained.language_encoder.transformer.model.parameters())


# ------------------------------------------------------------------ the chapter's models and tables
def test_the_chapters_three_models_train_side_by_side_and_ptae_is_cached():
    from pgae_lite.config import get_profile
    from pgae_lite.model.prae import PRAE
    from pgae_lite.model.ptae import PTAE
    from pgae_lite.model.pvae import PVAE
    from pgae_lite.runs.pipeline import model_folder, trained_models
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.checkpoint import CHECKPOINT

    trainings, profile = [TRAININGS[n] for n in ("PRAE-8", "PVAE", "PTAE")], get_profile("smoke")
    models = trained_models(trainings, profile, seed=0, device="cpu", progress=False, workers=1)
    assert list(models) == ["PRAE-8", "PVAE", "PTAE"]
    assert type(models["PRAE-8"].model) is PRAE and isinstance(models["PVAE"].model, PVAE)
    assert models["PRAE-8"].model.cfg.binding.all_descriptions and isinstance(models["PTAE"].model, PTAE)
    checkpoints = {name: model_folder(trained.profile, name) / CHECKPOINT for name, trained in models.items()}
    written = {name: path.stat().st_mtime_ns for name, path in checkpoints.items()}
    again = trained_models(trainings, profile, seed=0, device="cpu", progress=False, workers=1)
    assert again["PRAE-8"].history == models["PRAE-8"].history          # the cached model
    assert {name: path.stat().st_mtime_ns for name, path in checkpoints.items()} == written   # loaded, not trained
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
    from pgae_lite.runs.rows import TRAININGS

    paper, book = get_profile("paper"), get_profile("book")
    prae_book = TRAININGS["PRAE"].profile(book, samples=864).train
    assert prae_book == replace(book.train, length_batches=False)       # the book's recipe is everyone's
    prae = TRAININGS["PRAE"].profile(paper, samples=864).train
    assert (prae.batch_size, prae.lr, prae.epochs) == (50, 1e-3, round(20_000 * 50 / 864))
    pvae = TRAININGS["PVAE"].profile(paper, samples=864).train
    assert (pvae.batch_size, pvae.lr, pvae.epochs) == (100, 1e-4, round(15_000 * 100 / 864))
    assert (pvae.weight_decay, pvae.schedule, pvae.clip) == (0.0, "constant", None)   # Adam, as the paper's
    bert = TRAININGS["PVAE-BERT-tuned"].profile(paper, samples=864).train
    assert (bert.batch_size, bert.lr, bert.epochs) == (100, 1e-4, round(40_000 * 100 / 864))


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
    checkpoint = tmp_path / "PVAE-seed0" / "checkpoint.pt"                      # the one loop's checkpoint
    assert not (tmp_path / "PVAE-seed0" / "family.pt").exists()
    saved = checkpoint.stat().st_mtime_ns
    again = reproduce(original_data, **args)                                    # loaded, not trained again
    assert checkpoint.stat().st_mtime_ns == saved
    assert again["rows"]["PVAE"]["mean"] == report["rows"]["PVAE"]["mean"]


def test_a_family_model_of_an_older_recipe_version_is_refused_not_loaded(toy_short, tmp_path):
    """A PRAE checkpoint whose recipe has an older RECIPE_VERSION: load_model refuses it, and the loop will not
    resume from it."""
    from pgae_lite.config import get_profile
    from pgae_lite.runs.pipeline import load_model
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.checkpoint import CHECKPOINT, CHECKPOINT_KEYS
    from pgae_lite.train.config import RECIPE_VERSION
    from pgae_lite.train.loop import train
    from pgae_lite.util.storage import CheckpointMismatchError, load_torch, save_torch

    prof = TRAININGS["PRAE"].profile(get_profile("smoke", epochs=1, max_train_samples=16, batch_size=16))
    path = tmp_path / "PRAE-seed0" / CHECKPOINT
    trained = train(toy_short, prof, out_dir=path.parent, device="cpu", progress=False)
    model, _, _ = load_model(path, device="cpu", dataset=toy_short)             # this version's: loaded
    assert type(model) is type(trained.model)
    saved = load_torch(path, CHECKPOINT_KEYS)
    saved["profile"]["recipe_version"] = RECIPE_VERSION - 1                     # as the family code saved it
    save_torch(saved, path)
    with pytest.raises(CheckpointMismatchError, match=f"trained with recipe version {RECIPE_VERSION - 1}; "
                                                      f"this pgae_lite reads version {RECIPE_VERSION}"):
        load_model(path, device="cpu")
    with pytest.raises(CheckpointMismatchError, match=f"trained with recipe version {RECIPE_VERSION - 1}; "
                                                      f"this pgae_lite reads version {RECIPE_VERSION}"):
        train(toy_short, prof, out_dir=path.parent, device="cpu", progress=False)     # nor resumes from it
