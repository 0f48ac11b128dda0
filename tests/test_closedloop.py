"""Closed loop: the decoder's step API, and a real model driving the real simulator (smoke profile)."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from pgae_lite.config import ModelConfig, get_profile
from pgae_lite.evaluate.table1 import predict
from pgae_lite.model.pgae import ActionDecoder
from pgae_lite.robot.closedloop import (
    animate,
    closed_loop,
    compare,
    execute_batch,
    open_loop,
    pattern_for,
    success_summary,
    words_of,
)
from pgae_lite.runs.data import simulated_dataset, trained_cae
from pgae_lite.sim import Execution, Simulation, execute_trajectory
from pgae_lite.sim.dataset import load_episode
from pgae_lite.train.loop import train
from pgae_lite.world.patterns import ARRANGEMENTS, Pattern, pattern_number

SMOKE = get_profile("smoke").data
PATTERN = 116   # slide the left cube (cyan) fast: a test pattern of the smoke set, 50 steps


@pytest.mark.parametrize("cell", ["lstm", "peephole"])
@pytest.mark.parametrize("feedback", ["predicted", "start"])
@pytest.mark.parametrize("stride", [1, 2])
def test_stepping_the_decoder_gives_what_forward_gives(cell, feedback, stride):
    decoder = ActionDecoder(ModelConfig(units=16, hidden=8, cell=cell, joint_feedback=feedback,
                                        time_stride=stride)).eval()
    h, vision, start = torch.randn(3, 8), torch.randn(3, 7, 30), torch.rand(3, 5) * 2 - 1
    lengths = torch.tensor([7, 4, 7])
    with torch.no_grad():
        whole = decoder(h, vision, start, steps=lengths)              # (3, 7, 5)
        state, j, stepped = decoder.begin(h), start, []
        for t in range(0, 7, stride):                                 # a step writes `stride` poses
            j, state = decoder.step(state, vision[:, t], j, start)
            stepped.append(j.reshape(3, stride, 5))
    stepped = torch.cat(stepped, 1)[:, :7]
    valid = torch.arange(7)[None] < lengths[:, None]
    assert torch.allclose(whole[valid], stepped[valid], atol=1e-5)


@pytest.fixture(scope="module")
def smoke(smoke_episodes):
    """The smoke dataset, its CAE and a PGAE trained on it for a few seconds."""
    data = simulated_dataset(get_profile("smoke"), "cpu", progress=False)
    cae, _ = trained_cae(get_profile("smoke"), "cpu", progress=False)
    trained = train(data, get_profile("smoke"), device="cpu", progress=False)
    return data, cae, trained.model, trained.normaliser


def test_closed_loop_starts_like_the_recording_and_is_deterministic(smoke):
    data, cae, model, normaliser = smoke
    run = closed_loop(model, cae, normaliser, PATTERN, 0, config=SMOKE)
    assert run.frames.shape == (50, 120, 160, 3) and run.frames.dtype == np.uint8
    assert run.joints.shape == run.measured.shape == run.targets.shape == (50, 5)
    assert run.description == "slide cyan fast"
    # Step 0 is the recording's step 0, bit for bit; so the first poses are the paper's execute's.
    episode = load_episode(SMOKE, PATTERN, 0)
    assert np.array_equal(run.frames[0], episode.images[0])
    assert np.allclose(run.joints[0], episode.joints[0], atol=1e-6)
    i = int(np.flatnonzero(data.ids == f"sim/{PATTERN:03d}-0")[0])
    paper = predict(model, data.subset([i]), normaliser, "execute").joints[0]
    k = model.cfg.time_stride                                  # the first decoder step reads v_0 only
    assert k == 3 and np.allclose(run.joints[:k + 1], paper[:k + 1], atol=1e-4)
    again = closed_loop(model, cae, normaliser, PATTERN, 0, config=SMOKE)
    assert np.array_equal(run.joints, again.joints) and np.array_equal(run.frames, again.frames)
    assert np.array_equal(run.displacement, again.displacement)
    # Precomputed language features go through model.encode(batch, language=...): here the model's own.
    batch = execute_batch(np.zeros(30), np.zeros(5), words_of(PATTERN), "cpu")
    with torch.no_grad():
        features = model.language_encoder(batch.lang_tokens, batch.lang_lengths)
    told = closed_loop(model, cae, normaliser, PATTERN, 0, config=SMOKE, language=features)
    assert np.array_equal(run.joints, told.joints)
    html = animate(run, every=25, size=1, dpi=20).to_jshtml()
    assert html.count("data:image/png;base64") == 3                       # steps 0, 25 and the last, 49
    # The result's check is the simulator's: sending the same motor targets to a fresh world agrees.
    sim = Simulation(SMOKE.sim)
    sim.reset(PATTERN, 0, SMOKE.base_seed, render=False)
    replay = sim.run(run.targets, render=False)
    assert replay.passed == run.passed and np.array_equal(replay.displacement, run.displacement)
    assert isinstance(run, Execution) and isinstance(replay, Execution)               # one type for both
    assert (replay.pattern, replay.variation) == (run.pattern, run.variation) == (PATTERN, 0)


def test_executing_the_recorded_joints_passes_the_check(smoke_episodes):
    episode = load_episode(SMOKE, PATTERN, 0)
    tracked = open_loop(episode.joints, PATTERN, 0, config=SMOKE)
    assert tracked.passed, tracked.check.reason
    assert np.abs(tracked.measured - episode.joints).max() < 0.02          # the arm follows the recording
    # Sent straight to the motors, the recorded (measured) joints lag a second time.
    direct = open_loop(episode.joints, PATTERN, 0, config=SMOKE, tracking=False)
    assert np.abs(direct.measured - episode.joints).max() > 0.05
    same = execute_trajectory(episode.joints, PATTERN, 0, SMOKE.sim, SMOKE.base_seed, render=False)
    assert same.passed == direct.passed and np.allclose(same.displacement, direct.displacement, atol=1e-3)


def test_compare_gives_one_row_per_episode_and_a_summary(smoke):
    data, cae, model, normaliser = smoke
    table = compare(model, cae, normaliser, data, limit=2, config=SMOKE, progress=False)
    assert len(table) == 2 and table["id"].str.startswith("sim/").all()
    assert {"open_passed", "closed_passed", "open_nrmse", "closed_nrmse"} <= set(table.columns)
    summary = success_summary(table)
    assert summary.loc["all", "n"] == 2
    assert 0 <= summary.loc["all", "closed loop %"] <= 100


def test_pattern_for_finds_every_pattern_from_its_description():
    for number in range(144):
        pat = Pattern.from_number(number)
        arrangement = ARRANGEMENTS.index((pat.left, pat.right))
        assert pattern_for(f"{pat.action} {pat.colour} {pat.speed}", arrangement) == number
    assert pattern_for("move-sideways azure quickly", 0) == pattern_number(1, 0, 5)   # red+blue: blue is the right cube
    with pytest.raises(ValueError, match="no yellow cube"):
        pattern_for("push yellow slowly", 0)
