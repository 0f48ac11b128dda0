"""Closed loop: the trained model drives the simulated robot, one step at a time.

Paper, Sec. 3 (Action Autoencoder) and Sec. 4 (the "execute" task). In the
paper's execute the action decoder reads, at every step, the visual features of
the *recorded* execution (authors' code), so it never sees what its own joints
do: it is open-loop. Here the model's own motion makes the images it reads::

    frame_0 = NICO at its start pose                      (as every recording starts)
    h       = encode(signal execute + description, [v_0; j_0])
    for t = 0, k, 2k, ... < T-1:                          (k = the model's time_stride, 3 in the book)
        ĵ_{t+1} .. ĵ_{t+k} = decoder.step(v_t, ĵ_t)        (ĵ_0 = j_0)
        for each s = t+1 .. t+k: move the arm so that its joints reach ĵ_s;
            step the physics; render frame_s
        v_{t+k} = Normaliser(CAE(frame_{t+k}))
    passed  = the simulator's check: did the named cube move the named way?

Time alignment, as in a recording (:mod:`pgae_lite.sim.record`): the arm
starts at ``HOME_POSE``, every recorded step commands joint targets, runs the
physics (3 substeps) and then renders frame t and measures joints t, so image t
shows the arm at joints t; step 0 commands ``HOME_POSE`` itself. We do exactly
that, so frame 0 and j_0 are bit-identical to the recording's.

Tracking. The recorded joints are *measured*, not the motor targets. A
pybullet position motor closes a fixed share of the gap to its target each
physics step (gain 0.1), so the measured joints trail the targets by 2-3
steps. Sending the model's ĵ_t, or the recorded joints, straight to the motors
therefore lags twice: replaying the recorded joints of the 216 simulated test
episodes that way fails 24 of them (23 of the 24 fast left slides). With
``tracking=True`` (default) we send the target that makes the measured joints
reach ĵ_t after one step, u = q + (ĵ_t − q) / α with α = 1 − 0.9³; the same
replay then passes 216 of 216. ``tracking=False`` sends ĵ_t as it is (what
:func:`~pgae_lite.sim.record.execute_trajectory` does).

:func:`open_loop` executes a joint trajectory computed in advance (e.g. the
paper's execute, from :func:`pgae_lite.evaluate.table1.predict`) the same way;
:func:`compare` runs both over a set of episodes.

Free-form instructions, executed both ways, are in :mod:`pgae_lite.robot.instructions`.
"""
from __future__ import annotations

import time

import numpy as np
import pandas as pd
import torch
from tqdm.auto import tqdm

from pgae_lite.cae import ChannelSeparatedCAE, extract_features
from pgae_lite.config import PROFILES
from pgae_lite.data.dataset import PGAEDataset, description_text
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import joint_nrmse, predict
from pgae_lite.freeform.refusals import check_instruction
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import SignalBatch, make_batch, signal_ids
from pgae_lite.sim.dataset import DatasetConfig
from pgae_lite.sim.record import Execution, Simulation, shared_simulation
from pgae_lite.sim.robot import HOME_POSE
from pgae_lite.viz import animate_frames
from pgae_lite.world.patterns import ACTION_SIDES, ARRANGEMENTS, Pattern, pattern_number
from pgae_lite.world.words import DESCRIPTIONS, WORD_INDEX, parse_description, tokenize

#: pybullet's default gain of a position motor (Robot.set_targets sets none): each physics
#: step closes this share of the gap between the joint and its target.
POSITION_GAIN = 0.1


def _drive(sim: Simulation, desired: np.ndarray, tracking: bool, render: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """One step towards ``desired`` joints (5,) radians; returns the motor target sent and NICO's view."""
    target = np.asarray(desired, dtype=np.float64)
    if tracking:                      # the target that brings the measured joints to ``desired`` in one step
        alpha = 1.0 - (1.0 - POSITION_GAIN) ** sim.config.substeps
        q = sim.joints()
        target = q + (target - q) / alpha
    return target, sim.step(target, render)


def _start(sim: Simulation, config: DatasetConfig, pattern: int, variation: int, render: bool) -> np.ndarray | None:
    """Build the episode's world and take step 0 at the start pose, exactly as a recording does."""
    sim.reset(pattern, variation, config.base_seed, render=False)
    return sim.step(np.array(HOME_POSE), render)


def words_of(pattern: int, description: str | None = None, alternative: int = 0) -> tuple[str, ...]:
    """The three words to give the model: ``description`` (checked), else the pattern's ``alternative``-th."""
    if description is None:
        return tuple(description_text(Pattern.from_number(pattern).descriptions()[alternative % DESCRIPTIONS]).split())
    parse_description(description)             # a helpful LanguageError for a wrong word or order
    return tuple(tokenize(description))


def execute_batch(vision: np.ndarray, joints: np.ndarray, words: tuple[str, ...],
                  device: torch.device | str = "cpu") -> SignalBatch:
    """The signal ``execute`` with ``words`` and the first step (vision (30,), joints (5,), model units).

    Built by :func:`~pgae_lite.model.signals.make_batch`, as in evaluation, from a one-step "dataset".
    """
    one_step = {
        "joints": torch.as_tensor(joints, dtype=torch.float32, device=device).reshape(1, 1, -1),
        "vision": torch.as_tensor(vision, dtype=torch.float32, device=device).reshape(1, 1, -1),
        "vision_opposite": torch.zeros(1, 1, len(vision), device=device),
        "lengths": torch.ones(1, dtype=torch.long, device=device),
        "descriptions": torch.tensor([[WORD_INDEX[w] for w in words]] * 8, device=device)[None],  # (1, 8, 3)
    }
    index = torch.zeros(1, dtype=torch.long)
    return make_batch(one_step, index, signal_ids("execute", 1), index)


@torch.no_grad()
def closed_loop(model: PGAE, cae: ChannelSeparatedCAE, normaliser: Normaliser, pattern: int,
                variation: int = 0, description: str | None = None, *, alternative: int = 0,
                config: DatasetConfig | None = None, steps: int | None = None,
                language: torch.Tensor | None = None, tracking: bool = True) -> Execution:
    """Let ``model`` execute a description in the scene of (``pattern``, ``variation``), seeing its own motion.

    ``description`` defaults to the pattern's ``alternative``-th description;
    the check is always the pattern's action. ``config`` is the simulated
    dataset's (its base seed and simulator settings; default: the book
    profile's), so the cubes lie where they lay in the recording. ``steps``
    defaults to the pattern's length (100 slow, 50 fast). ``language`` (1, D):
    precomputed language features in place of the words, e.g. free text through
    a pretrained encoder (``model.language_encoder.encode_texts([text])``),
    passed on as ``model.encode(batch, language=language)``; ``description`` is
    then only the rollout's label, and the instruction checked: text the robot will not act on
    (:mod:`pgae_lite.freeform.refusals`) raises :class:`~pgae_lite.freeform.refusals.CannotDo`.
    """
    config = config or PROFILES["book"].data
    model.eval()
    device = next(model.parameters()).device
    if language is None:
        words = words_of(pattern, description, alternative)
        text = " ".join(words)
    else:                     # the features carry the words: the batch's own tokens go unused
        words, text = words_of(pattern, None, alternative), description or ""
        if text and model.language_encoder.reads_free_text:   # free text: first, whether the robot can
            p = Pattern.from_number(pattern)
            check_instruction(text, model.language_encoder, (p.left, p.right))
    steps = steps or Pattern.from_number(pattern).steps

    def features(frame: np.ndarray) -> torch.Tensor:          # frame -> v_t (1, 30), model units
        v = normaliser.vision_to_model(extract_features(cae, frame[None]))
        return torch.from_numpy(v).to(device)

    sim = shared_simulation(config.sim, config.the_world)
    frame = _start(sim, config, pattern, variation, render=True)
    measured, frames, targets = [sim.joints()], [frame], [np.array(HOME_POSE)]
    cubes = [sim.cube_positions()]                                 # (2, 3) per step, for the book's page
    v = features(frame)
    j = torch.from_numpy(normaliser.joints_to_model(measured[0])).to(device)[None]   # j_0 (1, 5)
    batch = execute_batch(v[0], j[0], words, device)
    h, _ = model.encode(batch) if language is None else model.encode(batch, language=language)

    decoder, start, k = model.action_decoder, batch.start_joints, model.cfg.time_stride
    state, joints = decoder.begin(h), [start]
    for t in range(0, steps - 1, k):                            # t = 0, k, 2k, ...: the frames the model reads
        poses, state = decoder.step(state, v, j, start)          # ĵ_{t+1} .. ĵ_{t+k} from v_t and ĵ_t, (1, 5k)
        for j in poses.reshape(k, 1, -1)[:steps - 1 - t]:        # k x (1, 5), within the episode
            target, frame = _drive(sim, normaliser.joints_to_data(j)[0].cpu().numpy(), tracking, render=True)
            joints.append(j)
            frames.append(frame)
            targets.append(target)
            measured.append(sim.joints())
            cubes.append(sim.cube_positions())
        v = features(frame)                                      # v_{t+k}
    return Execution(pattern, variation, np.stack(frames), normaliser.joints_to_data(torch.cat(joints)).cpu().numpy(),
                     np.array(measured), np.array(targets), sim.cube_displacement(), sim.check(), text,
                     np.array(cubes))


def open_loop(joints: np.ndarray, pattern: int, variation: int = 0, *, description: str = "",
              config: DatasetConfig | None = None, tracking: bool = True, render: bool = False) -> Execution:
    """Execute a joint trajectory computed in advance, (T, 5) radians, step 0 = start joints.

    E.g. the paper's execute (``predict(..., "execute").joints``) or a recording's own joints.
    Step 0 commands the start pose, as the recordings do; then each step drives towards ``joints[t]``.
    """
    config = config or PROFILES["book"].data
    sim = shared_simulation(config.sim, config.the_world)
    frame = _start(sim, config, pattern, variation, render)
    measured, frames, targets = [sim.joints()], [frame], [np.array(HOME_POSE)]
    for desired in joints[1:]:
        target, frame = _drive(sim, desired, tracking, render)
        frames.append(frame)
        targets.append(target)
        measured.append(sim.joints())
    return Execution(pattern, variation, np.stack(frames) if render else None, np.asarray(joints, dtype=np.float32),
                     np.array(measured), np.array(targets), sim.cube_displacement(), sim.check(), description)


def variation_of(sample_id: str) -> int:
    """A simulated sample's variation, from its id ``sim/PPP-V``."""
    if not str(sample_id).startswith("sim/"):
        raise ValueError(f"sample {sample_id!r} is not from our simulator: only simulated episodes can be executed")
    return int(str(sample_id).rsplit("-", 1)[1])


def _nrmse(pred: np.ndarray, target: np.ndarray, length: int, joint_range: float) -> float:
    """nRMSE (%) of one sample over its predicted steps 1..length-1, as Table 1's."""
    return joint_nrmse(pred[:length], target[:length], joint_range)[0]


def spread(n: int, limit: int | None) -> np.ndarray:
    """Indices 0..n-1, or ``limit`` of them evenly spread."""
    rows = np.arange(n)
    if limit is not None and limit < n:
        rows = rows[np.linspace(0, n, limit, endpoint=False).astype(int)]
    return rows


def execute_episode(model: PGAE, cae: ChannelSeparatedCAE, normaliser: Normaliser, episodes: PGAEDataset,
                    i: int, planned: np.ndarray, text: str, joint_range: float, *,
                    language: torch.Tensor | None = None, closed: bool = True,
                    config: DatasetConfig | None = None, tracking: bool = True) -> dict:
    """Episode ``i`` of ``episodes`` executed open loop (``planned`` joints, (T, 5)) and closed loop: a table row.

    ``text`` is what the model was told; ``language`` (1, D), if given, its features (see :func:`closed_loop`).
    """
    pattern, variation, length = int(episodes.pattern[i]), variation_of(episodes.ids[i]), int(episodes.lengths[i])
    pat, recorded = Pattern.from_number(pattern), episodes.joints[i]
    row = {"id": episodes.ids[i], "pattern": pattern, "variation": variation, "action": pat.action,
           "side": pat.side, "speed": pat.speed, "description": text}
    t0 = time.perf_counter()
    opened = open_loop(planned[:length], pattern, variation, description=text, config=config, tracking=tracking)
    row.update(open_passed=opened.passed, open_nrmse=_nrmse(opened.joints, recorded, length, joint_range),
               open_reason=opened.check.reason, open_seconds=time.perf_counter() - t0)
    if closed:
        t0 = time.perf_counter()
        run = closed_loop(model, cae, normaliser, pattern, variation, text, config=config, tracking=tracking,
                          language=language)
        row.update(closed_passed=run.passed, closed_nrmse=_nrmse(run.joints, recorded, length, joint_range),
                   closed_reason=run.check.reason, closed_seconds=time.perf_counter() - t0)
    return row


def compare(model: PGAE, cae: ChannelSeparatedCAE, normaliser: Normaliser, data: PGAEDataset,
            split: str = "test", *, limit: int | None = None, config: DatasetConfig | None = None,
            tracking: bool = True, progress: bool = True) -> pd.DataFrame:
    """Open loop (the paper's execute) and closed loop on the episodes of ``split``; one row per episode.

    ``data`` is the simulated dataset the model was evaluated on (its joint range
    is nRMSE's denominator); ``limit`` takes that many episodes, evenly spread
    over the split. Sample i of the split is given its description i mod 8, as
    in evaluation. nRMSE (%) compares the joints each loop asked for with the
    recorded ones.
    """
    subset = data.split(split)
    pred = predict(model, subset, normaliser, "execute")          # open loop: recorded vision at every step
    joint_range = data.joint_range()
    return pd.DataFrame([
        execute_episode(model, cae, normaliser, subset, i, pred.joints[i],
                         description_text(subset.descriptions[i, i % DESCRIPTIONS]), joint_range,
                         config=config, tracking=tracking)
        for i in tqdm(spread(len(subset), limit), desc="open vs closed loop", unit="ep", disable=not progress)])


def success_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Success rate (%) and mean nRMSE (%) of each loop in the table: over all, per action and per speed."""
    groups = [("all", table)] + [(name, g) for key in ("action", "speed") for name, g in table.groupby(key, sort=False)]
    loops = [loop for loop in ("open", "closed") if f"{loop}_passed" in table]
    return pd.DataFrame([{
        "group": name, "n": len(g),
        **{f"{loop} loop %": 100 * g[f"{loop}_passed"].mean() for loop in loops},
        **{f"{loop} nRMSE %": g[f"{loop}_nrmse"].mean() for loop in loops}}
        for name, g in groups]).set_index("group")


#: The message of :func:`pattern_for`'s error as a template (``str.format``, named fields); the page fills it too.
MESSAGES: dict[str, str] = {
    "no_cube_in_arrangement": "there is no {colour} cube in arrangement {arrangement} ({left} left, {right} right)",
}


def pattern_for(description: str | tuple[str, str, str], arrangement: int) -> int:
    """The pattern a description asks for in cube arrangement ``arrangement`` (0-11, see ARRANGEMENTS).

    ``description``: its text, or its parse (:func:`~pgae_lite.world.words.parse_description`'s).
    """
    action, colour, speed = parse_description(description) if isinstance(description, str) else description
    left, right = ARRANGEMENTS[arrangement]
    if colour not in (left, right):
        raise ValueError(MESSAGES["no_cube_in_arrangement"].format(colour=colour, arrangement=str(arrangement),
                                                                   left=left, right=right))
    side = "L" if colour == left else "R"
    return pattern_number(("slowly", "fast").index(speed), arrangement, ACTION_SIDES.index((action, side)))


def animate(rollout: Execution, every: int = 2, fps: float = 10.0, size: float = 2.8, dpi: int = 72):
    """The rollout seen from NICO's eye, with its measured joints: a matplotlib animation.

    Show it in a notebook with ``IPython.display.HTML(animate(rollout).to_jshtml())``
    (see :func:`pgae_lite.viz.scenes.animate_frames`).
    """
    if rollout.frames is None:
        raise ValueError("this rollout has no frames: run open_loop(..., render=True), or use closed_loop")
    verdict = "done" if rollout.passed else f"failed ({rollout.check.reason})"
    return animate_frames({"NICO's eye": rollout.frames}, joints=rollout.measured, every=every, fps=fps,
                          size=size, dpi=dpi, title=f"{rollout.description}: {verdict}")


__all__ = ["closed_loop", "open_loop", "compare", "success_summary", "execute_batch", "words_of", "pattern_for",
           "animate", "execute_episode", "variation_of", "spread", "POSITION_GAIN"]
