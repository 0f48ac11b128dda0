"""Lab: a new task, describing what the opposite agent does (paper Sec. 4, the opposite agent: PGAE-opposite).

The book's PGAE describes NICO's own actions: its action encoder reads x_t = [v_t; j_t], NICO's view and joints.
The new task shows it the other agent's action instead, seen by NICO's eye while NICO sits still:

    x_t^opp = [v_t^opp; j_1],   t = 1, ..., M        (the other agent's visual features, NICO's first joints held)

and asks for the description, while the action decoder holds NICO's first pose: it reads NICO's own view
[v_1; j_1] at every step and must reproduce j_1 (NICO has not moved). The student writes those inputs,

    task(vision, vision_opposite, joints, lengths) -> (action_input, held)

for a batch of B samples (normalised tensors (B, T, 30), (B, T, 30), (B, T, 5), (B,)), each output (B, T, 35):
``action_input`` the encoder's [v_t^opp; j_1], ``held`` the decoder's [v_1; j_1] at every step. The lab trains
PGAE at a short budget with half of its ``describe`` samples turned into the new task (the opposite share,
``TrainConfig.opposite_prob``, as the authors' 1/2) and measures ``describe`` on the test actions of both
agents. The baseline (``BASELINE = None``) is the book's PGAE, which never sees the opposite view.

Deviation from paper: the paper's two-view model shows the other agent to every signal but ``execute``
(the package's ``make_batch(opposite=...)``, chapter 06); the lab's new task is ``describe`` alone, one task.
"""
from __future__ import annotations

from typing import Callable

import torch

from pgae_lite.config import Profile, get_profile
from pgae_lite.evaluate.table1 import predict
from pgae_lite.exercises.result import CheckResult, _call, _compare, _pair, _unchanged
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import DESCRIBE, make_batch
from pgae_lite.runs.data import simulated_dataset
from pgae_lite.train.loop import train
from pgae_lite.util.checks import MAX_SEED, whole_number
from pgae_lite.world.words import DESCRIPTIONS, VOCABULARY

TITLE = "A new task: describing what the opposite agent does"
STUDENT_NAME = "opposite_inputs"        # the student's component, in the lab's notebook
VISION, JOINTS = 30, 5                  # v_t in R^30, j_t in R^5
# Deviation from the book: the lab's budget, a fifth of the recipe's 300 epochs (a profile with fewer keeps its own).
# At 30 epochs, trained with the task, the model had learnt to describe neither view yet (measured first there).
EPOCHS = 60
OPPOSITE_SHARE = 0.5                    # of the describe samples, those that show the other agent (authors: 1/2)
EQUATION = "action_input = [v_t^opp; j_1] for every step t; held = [v_1; j_1] (NICO's own view) for every step"

FIGURES = {"describe_opposite": "describe, the other agent's test actions (%)",
           "describe_self": "describe, NICO's own test actions (%)"}

Task = Callable[[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor], tuple[torch.Tensor, torch.Tensor]]


# ------------------------------------------------------------------ the reference change
def describe_opposite(vision: torch.Tensor, vision_opposite: torch.Tensor, joints: torch.Tensor,
                      lengths: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The new task's inputs: the encoder's [v_t^opp; j_1] and the decoder's [v_1; j_1], each (B, T, 35)."""
    T = joints.shape[1]
    first = joints[:, :1].expand(-1, T, -1)                          # j_1, held: (B, T, 5)
    action_input = torch.cat([vision_opposite, first], dim=2)        # x_t^opp = [v_t^opp; j_1]: (B, T, 35)
    held = torch.cat([vision[:, :1], joints[:, :1]], dim=2).expand(-1, T, -1)   # [v_1; j_1], held: (B, T, 35)
    return action_input, held


BASELINE, REFERENCE = None, describe_opposite


# ------------------------------------------------------------------ mistakes the check must name
def _held(x: torch.Tensor, step: torch.Tensor) -> torch.Tensor:
    """``x`` (B, T, D) at each sample's ``step`` (B,), held for T steps."""
    return x[torch.arange(len(x)), step][:, None].expand_as(x)


def _last(lengths: torch.Tensor) -> torch.Tensor:
    return (lengths - 1).long()


def _own_view(vision, vision_opposite, joints, lengths):
    """Wrong: the encoder sees NICO's own view."""
    return describe_opposite(vision, vision, joints, lengths)


def _moving_joints(vision, vision_opposite, joints, lengths):
    """Wrong: NICO's joints move in the encoder's input."""
    return torch.cat([vision_opposite, joints], 2), describe_opposite(vision, vision_opposite, joints, lengths)[1]


def _held_last(vision, vision_opposite, joints, lengths):
    """Wrong: the decoder holds NICO's last pose (as describing its own action does)."""
    step = _last(lengths)
    return (describe_opposite(vision, vision_opposite, joints, lengths)[0],
            torch.cat([_held(vision, step), _held(joints, step)], 2))


WRONG = {
    "NICO's own view": (_own_view, "the other agent's view"),
    "joints not held": (_moving_joints, "NICO sits still"),
    "held at the last step": (_held_last, "hold the FIRST step"),
}


# ------------------------------------------------------------------ the check
def _inputs(gen: torch.Generator, batch: int, steps: int) -> dict[str, torch.Tensor]:
    """Random normalised tensors as the dataset's: each sample its length (one of them all ``steps``)."""
    lengths = torch.randint(2, steps + 1, (batch,), generator=gen)
    lengths[0] = steps
    return {"vision": torch.randn(batch, steps, VISION, generator=gen),
            "vision_opposite": torch.randn(batch, steps, VISION, generator=gen),
            "joints": torch.randn(batch, steps, JOINTS, generator=gen), "lengths": lengths,
            "descriptions": torch.randint(1, len(VOCABULARY), (batch, DESCRIPTIONS, 3), generator=gen)}


def _mistakes(d: dict[str, torch.Tensor]) -> tuple[list, list]:
    """Known mistakes: (hint, action_input) and (hint, held) as a student's function would give them."""
    v, o, j, n = d["vision"], d["vision_opposite"], d["joints"], d["lengths"]
    first, last = torch.zeros_like(n), _last(n)
    both = lambda vis, step: torch.cat([_held(vis, step), _held(j, step)], 2)      # noqa: E731 - [v; j] held
    encoder = [
        ("the action encoder sees NICO's own view: use vision_opposite, the other agent's view",
         torch.cat([v, _held(j, first)], 2)),
        ("NICO's joints move in your input: NICO sits still while it watches, so hold j_1, its first joints",
         torch.cat([o, j], 2)),
        ("this is NICO's own action (its view, its moving joints): the task shows the other agent's view, "
         "with NICO's first joints held", torch.cat([v, j], 2)),
        ("the joints are held at the last step: NICO has not moved, hold the FIRST step, j_1",
         torch.cat([o, _held(j, last)], 2)),
        ("the other agent's view is held too: v_t^opp changes at every step, only the joints are held",
         torch.cat([_held(o, first), _held(j, first)], 2)),
        ("the layout is [vision; joints]: the 30 visual features first, then the 5 joints",
         torch.cat([_held(j, first), o], 2))]
    held = [
        ("you hold the last step, NICO's final pose (as describing its own action does); NICO has not moved: "
         "hold the FIRST step, [v_1; j_1]", both(v, last)),
        ("the decoder's sequence moves: describe holds one pose, NICO's first, [v_1; j_1] at every step",
         torch.cat([v, j], 2)),
        ("the decoder reads NICO's own view: hold v_1 of vision, not of vision_opposite", both(o, first)),
        ("the layout is [vision; joints]: the 30 visual features first, then the 5 joints",
         torch.cat([_held(j, first), _held(v, first)], 2))]
    return encoder, held


@torch.random.fork_rng(devices=[])
def check(task: Task, seed: int = 0, batch: int = 6, steps: int = 12) -> CheckResult:
    """Judge the new task's inputs against the package's ``make_batch`` for ``describe`` with the opposite view.

    Structure: ``task(vision, vision_opposite, joints, lengths)`` returns the pair (action_input, held), each
    (B, T, 35), and leaves its inputs unchanged. Behaviour: on random tensors of ``batch`` samples and ``steps``
    steps, both equal what :func:`~pgae_lite.model.signals.make_batch` feeds the action encoder and the action
    decoder, on every valid step of each sample; if not, the check names the mistake that gives the same numbers.
    """
    seed = whole_number("seed", seed, 0, MAX_SEED)
    batch, steps = whole_number("batch", batch, 2, 512), whole_number("steps", steps, 3, 200)
    result, gen = CheckResult("the new task's inputs"), torch.Generator().manual_seed(seed)
    if not callable(task):
        return result.fail(f"the task is {type(task).__name__}, not a function",
                           "define task(vision, vision_opposite, joints, lengths) -> (action_input, held)")
    d = _inputs(gen, batch, steps)
    result.note(f"inputs: {batch} samples of {steps} steps, lengths {d['lengths'].tolist()}")
    given = {k: d[k].clone() for k in ("vision", "vision_opposite", "joints", "lengths")}
    out = _call(result, "your task", task, *given.values())
    shape = (batch, steps, VISION + JOINTS)
    if not _pair(result, out, "action_input, held", "your task", shape):
        return result
    _unchanged(result, "your task", given, {k: d[k] for k in given})
    ref = make_batch(d, torch.arange(batch), torch.full((batch,), DESCRIBE), torch.zeros(batch, dtype=torch.long),
                     opposite=torch.ones(batch, dtype=torch.bool))
    valid = (torch.arange(steps)[None] < d["lengths"][:, None])[..., None].float()        # (B, T, 1)
    out_joints = torch.cat([ref.start_joints[:, None], ref.joint_target], 1)              # (B, T, 5)
    held_vision = torch.cat([ref.dec_vision, ref.dec_vision[:, -1:]], 1)                   # (B, T, 30), held
    expected = (ref.action_input, torch.cat([held_vision, out_joints], 2))
    for name, got, want, mistakes in zip(("action_input", "held"), out, expected, _mistakes(d)):
        if not isinstance(got, torch.Tensor) or got.shape != shape:
            _compare(result, name, got, want)                   # says what it is instead
            continue
        got = got.detach() * valid                              # padding steps are never read
        hint = next((h for h, t in mistakes if _same(got, t * valid)), None)
        if hint is not None and not _same(got, want * valid):
            result.fail(f"{name}: {hint}")                      # a known mistake, named on the failure's line
        elif not _compare(result, f"{name} on the valid steps", got, want * valid):
            result.note(f"compare each part with the equation: {EQUATION}")
    return result


def _same(a: torch.Tensor, b: torch.Tensor) -> bool:
    return a.shape == b.shape and bool(torch.allclose(a.double(), b.double(), atol=1e-5))


# ------------------------------------------------------------------ the student's run
class TaskPGAE(PGAE):
    """PGAE trained with the new task: each ``describe`` sample shows the other agent with the recipe's
    ``opposite_prob``, its inputs made by ``task`` (None: never, the book's PGAE)."""

    def __init__(self, cfg, lexicon, task: Task | None):
        super().__init__(cfg, lexicon)
        self.task = task

    def training_batch(self, data: dict[str, torch.Tensor], index: torch.Tensor, draws):
        """As :meth:`~pgae_lite.model.loss.LearnsFromSignals.training_batch`, with the new task's samples."""
        signal = draws.signals(index)
        alternative = draws.descriptions(len(index))
        dev = data["joints"].device
        task = (draws.views(len(index)) & (signal == DESCRIBE)).to(dev)      # the new task: describe, other agent
        batch = make_batch(data, index, signal, alternative)                  # NICO's own view, every sample
        if self.task is not None and task.any():
            rows = index.to(dev)[task]
            x, held = self.task(data["vision"][rows], data["vision_opposite"][rows], data["joints"][rows],
                                data["lengths"][rows])
            batch.action_input[task] = x                                      # [v_t^opp; j_1]
            batch.dec_vision[task] = held[:, :-1, :VISION]                    # v_1, held
            batch.start_joints[task] = held[:, 0, VISION:]                    # j_1 ...
            batch.joint_target[task] = held[:, 1:, VISION:]                   # ... held
        batch.action_input = draws.noise(batch.action_input)
        if "plan" in data:
            batch.plan_target = data["plan"][index.to(data["plan"].device)]
        return batch


def run(task: Task | None, seed: int = 0, profile: Profile | str | None = None,
        progress: bool = False) -> dict[str, float]:
    """Train PGAE with the new task made by ``task`` (None: without it) at the lab's budget; its figures.

    The profile's recipe with ``min(its epochs, EPOCHS)`` epochs, ``seed`` and, with a task, ``opposite_prob =
    OPPOSITE_SHARE``, on the profile's simulated data (the cache's: made if missing); ``describe`` accuracy (%)
    on the test split, from the other agent's view and from NICO's own.
    """
    base = profile if isinstance(profile, Profile) else get_profile(profile)
    seed = whole_number("seed", seed, 0, MAX_SEED)
    recipe = get_profile(base, seed=seed, epochs=min(base.train.epochs, EPOCHS),
                         opposite_prob=OPPOSITE_SHARE if task is not None else 0.0)
    data = simulated_dataset(recipe, progress=progress)
    torch.manual_seed(seed)                                   # the model's initialisation, as the loop's own
    model = TaskPGAE(recipe.model, recipe.data.the_world.lexicon, task)
    trained = train(data, recipe, progress=progress, model=model, name="PGAE with the new task")
    test = data.split("test")

    def describe(opposite: bool) -> float:
        said = predict(trained.model, test, trained.normaliser, "describe", opposite=opposite)
        return 100 * float(said.correct.mean())
    return {"describe_opposite": describe(True), "describe_self": describe(False)}


__all__ = ["BASELINE", "EPOCHS", "FIGURES", "OPPOSITE_SHARE", "REFERENCE", "STUDENT_NAME", "TITLE", "TaskPGAE",
           "WRONG", "check", "describe_opposite", "run"]
