"""Recording episodes: one pattern, NICO acting and the opposite agent acting.

Paper, Sec. 4 (Dataset): each of the 144 patterns is recorded 6 times with
small random variations; per step the 5 joint angles of NICO's left arm and a
120 x 160 image from NICO's eye. A second agent across the table performs the
same actions, seen from NICO's eye (the "opposite" view).

Who does what (our decisions, since the paper does not say):

- "left" and "right" (the pattern's cube side) are NICO's: the left cube is
  at +y. The opposite agent acts on the cube of the SAME COLOUR, which is on
  its own right when NICO calls it left.
- Each agent acts in its own frame: "push red" by the opposite agent moves
  the red cube away from the opposite agent, i.e. towards NICO. A slide moves
  the cube away from the other cube, the same way for both agents.
- While the opposite agent acts, NICO holds its start pose; the recorded
  joints are always NICO's own, from the episode where NICO acts.

Seeds: the episode (pattern, variation, base_seed) tries seeds
``episode_seed(pattern, variation, base_seed, attempt)`` for attempt = 0, 1, ...
(plain integers, no ``hash()``); the cube positions depend on (pattern,
variation, base_seed) only, the trajectory's offsets also on the attempt. An
attempt is kept when both agents' actions pass :func:`~pgae_lite.sim.actions.check_action`; after
``max_attempts`` failures :func:`record_episode` raises. The world is rebuilt
for every execution (``resetSimulation``), so the same arguments give
bit-identical joints and images.
"""
from __future__ import annotations

import functools
import logging
from dataclasses import dataclass, field

import numpy as np

from pgae_lite.sim.actions import (
    MAX_OFF_AXIS_RATIO,
    MAX_OTHER_MOVE,
    MIN_MOVE,
    ActionCheck,
    Plan,
    Variation,
    check_action,
    plan_action,
    sample_variation,
    world_direction,
)
from pgae_lite.sim.robot import JOINT_LIMITS, JOINT_NAMES, Robot
from pgae_lite.sim.scene import CUBE_Y, IMAGE_HEIGHT, IMAGE_WIDTH, TABLE_CENTRE_X, Scene, SceneLayout
from pgae_lite.world.colours import DEFAULT_WORLD, EXTENSION_NUMBERING, World
from pgae_lite.world.patterns import NUMBERING, Pattern

AGENTS = ("nico", "opposite")
log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SimConfig:
    """Everything that shapes a recording; plain values only (it keys the dataset cache)."""

    physics_hz: int = 240                     # physics time steps per second
    substeps: int = 3                         # physics steps per recorded step (3: 80 recorded steps/s,
                                              # a slow action lasts 1.25 s, a fast one 0.625 s)
    solver_iterations: int = 20               # contact solver iterations per physics step
    hand_friction: float = 0.3                # hand on cube: 0.3 x 0.5 = 0.15
    image_height: int = IMAGE_HEIGHT
    image_width: int = IMAGE_WIDTH
    # The jitters below are small on purpose: what a recording varies in that the model cannot see
    # (when each phase starts, how far the cube is pushed) puts a floor under any model's joint
    # error. With cube jitter +-1 cm, travel 8-10 cm and timing x[0.85, 1.15], the six recordings of
    # a pattern spread by 0.77% nRMSE around their mean (planned joints), above the paper's 0.44%;
    # with the values below, 0.34% (experiments/variation_floor.py).
    cube_jitter: float = 0.005                # cube centres move by up to +-5 mm in x and y
    distance: tuple[float, float] = (0.085, 0.095)   # planned cube travel (m), uniform
    lateral_jitter: float = 0.006             # contact point across the direction, +- (m)
    height_jitter: float = 0.004              # contact height, +- (m)
    timing_jitter: float = 0.02               # each phase's share of the steps, x [0.98, 1.02]
    ik_every: int = 4                         # IK at every 4th step of the hand path, linear in between
    min_move: float = MIN_MOVE                # check: cube moved >= 4 cm along the direction
    max_off_axis_ratio: float = MAX_OFF_AXIS_RATIO   # ... and sideways <= 0.5 x that
    max_other_move: float = MAX_OTHER_MOVE    # ... and the other cube < 1 cm
    max_attempts: int = 20                    # seeds tried before giving up


@dataclass
class Episode:
    """One recording of one pattern (see the module docstring for who does what)."""

    pattern: int                  # 0-143, pgae_lite.world.patterns numbering
    variation: int                # 0-5
    seed: int                     # the seed that produced this (valid) episode
    attempts: int                 # 1 if the first seed worked
    joints: np.ndarray            # (T, 5) float32 radians, T = 100 slow / 50 fast
    images: np.ndarray            # (T, 120, 160, 3) uint8, NICO's eye, NICO acting
    images_opposite: np.ndarray   # (T, 120, 160, 3) uint8, NICO's eye, the opposite agent acting
    displacement: np.ndarray      # (2, 3) float32 metres, left and right cube, NICO acting
    valid: bool
    info: dict = field(default_factory=dict)   # opposite displacement, planned joints, checks, tracking errors


@dataclass
class Execution:
    """One execution in the simulator: what was asked, what the arm did, what the cubes did.

    The outcome of driving one agent along a joint trajectory: :meth:`Simulation.run`
    (the recordings, :func:`execute_trajectory`) and the model's executions
    (:func:`pgae_lite.robot.closedloop.open_loop`, :func:`~pgae_lite.robot.closedloop.closed_loop`).
    """

    pattern: int                  # the scene (and the action the check expects), 0-143
    variation: int
    frames: np.ndarray | None     # (T, H, W, 3) uint8 from NICO's eye after each step, None if not rendered
    joints: np.ndarray            # (T, 5) joints asked for (our simulator's units: radians); for a model,
                                  # step 0 = the start joints, then ĵ_1..ĵ_{T-1}
    measured: np.ndarray          # (T, 5) measured joint angles (rad) after each step
    targets: np.ndarray           # (T, 5) the joint targets given at each step (rad)
    displacement: np.ndarray      # (2, 3) left and right cube (m, world frame)
    check: ActionCheck            # the pattern's action, checked for the acting agent
    description: str = ""         # the words given to the model ("" when none)
    cubes: np.ndarray | None = None   # (T, 2, 3) left and right cube centres (m, world) after each step,
                                      # when recorded (closed_loop); else None

    @property
    def passed(self) -> bool:
        return self.check.passed

    @property
    def tracking_error(self) -> np.ndarray:
        """Measured minus commanded joints (T, 5): large values mean the arm was blocked."""
        return self.measured - self.targets


def episode_seed(pattern: int, variation: int, base_seed: int = 0, attempt: int = 0) -> int:
    """The integer seed of one attempt: ((base_seed * 144 + pattern) * 100 + variation) * 100 + attempt.

    Patterns beyond 143 (:mod:`pgae_lite.world.colours`) reuse base_seed + 1's seeds (no clash).
    """
    return ((base_seed * 144 + pattern) * 100 + variation) * 100 + attempt


def _validate(pattern: int, variation: int, base_seed: int,
              world: World = DEFAULT_WORLD) -> Pattern:
    last = world.n_patterns - 1
    if not isinstance(pattern, (int, np.integer)) or not 0 <= pattern <= last:
        extended = f"; from 144: {EXTENSION_NUMBERING}" if last >= 144 else ""
        raise ValueError(f"pattern must be an integer 0-{last} "
                         f"({NUMBERING}{extended}), got {pattern!r}")
    if not isinstance(variation, (int, np.integer)) or not 0 <= variation < 100:
        raise ValueError(f"variation must be an integer 0-99 (the dataset uses 0-5), got {variation!r}")
    if not isinstance(base_seed, (int, np.integer)) or base_seed < 0:
        raise ValueError(f"base_seed must be a non-negative integer, got {base_seed!r}")
    return world.pattern(int(pattern))


def scene_layout(pattern: int, variation: int = 0, base_seed: int = 0,
                 config: SimConfig = SimConfig(),
                 world: World = DEFAULT_WORLD) -> SceneLayout:
    """Cube colours and (jittered) positions of a pattern and variation of ``world``."""
    pat = _validate(pattern, variation, base_seed, world)
    rng = np.random.default_rng([episode_seed(pattern, variation, base_seed), 0])   # stream 0: the layout
    jitter = rng.uniform(-config.cube_jitter, config.cube_jitter, size=(2, 2))       # (cube, xy)
    return SceneLayout(pat.left, pat.right,
                       left_xy=(TABLE_CENTRE_X + jitter[0, 0], CUBE_Y + jitter[0, 1]),
                       right_xy=(TABLE_CENTRE_X + jitter[1, 0], -CUBE_Y + jitter[1, 1]),
                       palette=world.rgba or None)


class Simulation:
    """A step-wise interface to one world, for recording and for closed-loop control::

        sim = Simulation()
        frame = sim.reset(pattern=0)          # NICO at its start pose; frame (120, 160, 3) uint8
        for q in joint_targets:               # e.g. a model's output, (T, 5) radians
            frame = sim.step(q)               # one recorded step (3 physics steps by default)
        sim.cube_displacement(), sim.check()  # (2, 3) metres; ActionCheck for the pattern

    Each :meth:`reset` rebuilds the world (bit-reproducible); ``agent="opposite"``
    makes the opposite agent act while NICO sits still. ``world`` (default: the
    paper's) gives the patterns' colours (:mod:`pgae_lite.world.colours`).
    """

    def __init__(self, config: SimConfig = SimConfig(),
                 world: World = DEFAULT_WORLD) -> None:
        self.config = config
        self.world = world
        self.scene: Scene | None = None
        self.pattern: Pattern | None = None
        self.variation: int | None = None

    def reset(self, pattern: int, variation: int = 0, base_seed: int = 0, agent: str = "nico",
              render: bool = True) -> np.ndarray | None:
        """Build the world of a pattern; ``agent`` ("nico" or "opposite") will act. Returns the first view."""
        if agent not in AGENTS:
            raise ValueError(f"unknown agent {agent!r}; the agents are: {', '.join(AGENTS)}")
        cfg = self.config
        layout = scene_layout(pattern, variation, base_seed, cfg, self.world)
        if self.scene is None:
            self.scene = Scene(layout, actor=agent, time_step=1.0 / cfg.physics_hz,
                               hand_friction=cfg.hand_friction, solver_iterations=cfg.solver_iterations,
                               image_size=(cfg.image_height, cfg.image_width))
        else:
            self.scene.rebuild(layout, agent)
        self.pattern = self.world.pattern(int(pattern))
        self.variation, self.agent = int(variation), agent
        return self.scene.render() if render else None

    @property
    def robot(self) -> Robot:
        """The acting robot."""
        return self.scene.robot(self.agent)

    def step(self, joint_targets: np.ndarray, render: bool = True) -> np.ndarray | None:
        """Drive the acting arm towards ``joint_targets`` (5,) radians for one recorded step.

        Targets are clipped to the joint limits. Returns NICO's view (or None).
        """
        q = np.asarray(joint_targets, dtype=np.float64)
        if q.shape != (len(JOINT_NAMES),):
            raise ValueError(f"joint targets must have shape ({len(JOINT_NAMES)},) for {', '.join(JOINT_NAMES)}; "
                             f"got {q.shape}")
        self.robot.set_targets(np.clip(q, *np.array(JOINT_LIMITS).T))
        self.scene.step(self.config.substeps)
        return self.scene.render() if render else None

    def joints(self) -> np.ndarray:
        """The acting arm's measured joint angles (5,) in radians."""
        return self.robot.joint_positions()

    def cube_displacement(self) -> np.ndarray:
        """(2, 3) metres: left and right cube, since reset."""
        return self.scene.cube_displacement()

    def cube_positions(self) -> np.ndarray:
        """(2, 3) metres: the left and right cube's centres now (world frame)."""
        return self.scene.cube_positions()

    def _cubes(self) -> tuple[np.ndarray, np.ndarray]:
        """Start positions of the pattern's cube and of the other cube (world, (3,) each)."""
        i = 0 if self.pattern.side == "L" else 1
        return self.scene.start_positions[i], self.scene.start_positions[1 - i]

    def check(self) -> ActionCheck:
        """Did the pattern's cube move the pattern's way (for the acting agent)?"""
        i = 0 if self.pattern.side == "L" else 1
        disp, cfg = self.cube_displacement(), self.config
        direction = world_direction(self.robot, self.pattern.action, *self._cubes())
        return check_action(direction, disp[i], disp[1 - i], cfg.min_move, cfg.max_off_axis_ratio,
                            cfg.max_other_move)

    def plan(self, rng: np.random.Generator | None = None) -> Plan:
        """The scripted plan of the pattern's action for the acting agent (random offsets from ``rng``)."""
        cfg = self.config
        variation = (Variation() if rng is None else
                     sample_variation(rng, cfg.distance, cfg.lateral_jitter, cfg.height_jitter, cfg.timing_jitter))
        return plan_action(self.robot, self.pattern.action, *self._cubes(), self.pattern.steps, variation,
                           cfg.ik_every)

    def run(self, joint_targets: np.ndarray, render: bool = True) -> Execution:
        """Drive the acting arm along ``joint_targets`` (T, 5) from its start pose; one frame per step."""
        targets = np.asarray(joint_targets, dtype=np.float64)
        if targets.ndim != 2 or targets.shape[1] != len(JOINT_NAMES):
            raise ValueError(f"joint trajectory must have shape (T, {len(JOINT_NAMES)}), got {targets.shape}")
        frames, measured = [], []
        for q in targets:
            frame = self.step(q, render)
            measured.append(self.joints())
            if render:
                frames.append(frame)
        return Execution(self.pattern.number, self.variation, np.stack(frames) if render else None, targets,
                         np.array(measured), targets, self.cube_displacement(), self.check())


@functools.lru_cache(maxsize=4)
def shared_simulation(config: SimConfig, world: World = DEFAULT_WORLD) -> Simulation:
    """One Simulation (one physics server) per config, world and process, reused by every caller (a recording's
    replay here, the closed loop of :mod:`pgae_lite.robot.closedloop`): each reset rebuilds the world."""
    return Simulation(config, world)


def execute_trajectory(joints: np.ndarray, pattern: int, variation: int = 0, config: SimConfig = SimConfig(),
                       base_seed: int = 0, render: bool = True, agent: str = "nico",
                       world: World = DEFAULT_WORLD) -> Execution:
    """Drive an agent (default NICO) along any joint trajectory (T, 5) in the scene of a pattern.

    The world is the one :func:`record_episode` uses for (pattern, variation,
    base_seed); the arm starts at :data:`~pgae_lite.sim.robot.HOME_POSE`. The
    result holds the frames, the measured joints, the cube displacement and
    whether the pattern's action succeeded, by the same check as the recordings.
    """
    sim = shared_simulation(config, world)
    sim.reset(pattern, variation, base_seed, agent, render=False)
    return sim.run(joints, render)


def record_episode(pattern: int, variation: int, config: SimConfig = SimConfig(),
                   base_seed: int = 0, world: World = DEFAULT_WORLD) -> Episode:
    """Record one episode: NICO acting and the opposite agent acting, both checked (see module docstring).

    ``world``: patterns beyond 143, their colours (:func:`pgae_lite.world.colours.with_colour`).
    """
    pat = _validate(pattern, variation, base_seed, world)
    sim = shared_simulation(config, world)
    failures = []
    for attempt in range(config.max_attempts):
        seed = episode_seed(pattern, variation, base_seed, attempt)
        rng = np.random.default_rng([seed, 1])                  # stream 1: the trajectories
        runs = {}
        for agent in AGENTS:
            sim.reset(pattern, variation, base_seed, agent, render=False)
            plan = sim.plan(rng)
            runs[agent] = sim.run(plan.joints)
            if not runs[agent].passed:
                failures.append(f"seed {seed} ({agent}): {runs[agent].check.reason}")
                log.info("pattern %d variation %d: %s; trying the next seed", pattern, variation, failures[-1])
                break
        else:
            me, other = runs["nico"], runs["opposite"]
            info = {"displacement_opposite": other.displacement.astype(np.float32),
                    "planned_joints": me.targets.astype(np.float32),
                    "check": me.check, "check_opposite": other.check,
                    "tracking_error": float(np.abs(me.tracking_error).max()),
                    "tracking_error_opposite": float(np.abs(other.tracking_error).max()),
                    "failures": failures}
            log.debug("pattern %d variation %d: seed %d, max tracking error %.3f / %.3f rad (NICO / opposite)",
                      pattern, variation, seed, info["tracking_error"], info["tracking_error_opposite"])
            return Episode(int(pattern), int(variation), seed, attempt + 1, me.measured.astype(np.float32),
                           me.frames, other.frames, me.displacement.astype(np.float32), True, info)
    raise RuntimeError(f"pattern {pattern} ({pat.code}), variation {variation}: "
                       f"no valid episode in {config.max_attempts} attempts; last failures: "
                       + " | ".join(failures[-3:]))


__all__ = ["SimConfig", "Episode", "Execution", "Simulation", "record_episode", "execute_trajectory",
           "shared_simulation", "episode_seed", "scene_layout", "AGENTS"]
