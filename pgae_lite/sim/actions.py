"""The 12 actions: push, pull or slide the left or right cube, slowly or fast.

Paper, Sec. 4 (Dataset): NICO pushes (away from itself), pulls (towards
itself) or slides (sideways) one of the two cubes, slowly (100 steps) or fast
(50 steps), with an inverse-kinematics solver. Our version, for either agent:

1. Where to push. Directions are in the acting agent's own frame (+x away
   from it, +y to its left): push = +x, pull = -x, and slide = sideways AWAY
   FROM THE OTHER CUBE (the left cube to the left, the right cube to the
   right), so the two cubes never collide. Seen from above, a slide therefore
   moves a cube the same way whichever agent does it.
2. A hand path through eight waypoints: the start pose's hand position, a
   point above the contact point, the contact point (beside the cube, on the
   side opposite to the direction), the end point (the cube has moved about
   ``distance``), the end point lifted, a point part of the way back, still
   rising (clearing the cubes), and the start position again, where the
   hand rests for the last few steps. Ending at rest at the start keeps the
   hand off the cubes in the last frames, so the camera sees both colours
   when the action is over (a hand left above a cube hides it from NICO's
   eye and makes "which colour was that?" hard to learn). Between
   waypoints the hand follows a minimum-jerk profile,
   s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, which starts and stops smoothly.
3. Joint angles by position-only IK along the path
   (:meth:`~pgae_lite.sim.robot.Robot.inverse_kinematics`), each solve seeded with the previous one.

The simulator then drives the joints with position control and contact
physics moves the cube; :func:`check_action` says whether it moved the way
the words say.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pgae_lite.sim.robot import HOME_POSE, Robot
from pgae_lite.sim.scene import CUBE_SIZE
from pgae_lite.world.words import ACTIONS

# Where the hand touches the cube: distance from the cube centre to the fingertip
# point, against the direction of motion (m). The hand is a 2.5 x 4.5 cm paddle
# pointing forward-down, so its front or back reaches ~1.7-2 cm beyond the fingertip
# (push, pull) and its side ~2.4 cm (slide).
CONTACT_OFFSET = {"push": CUBE_SIZE / 2 + 0.017, "pull": CUBE_SIZE / 2 + 0.020, "slide": CUBE_SIZE / 2 + 0.024}
APPROACH_GAP = {"push": 0.02, "pull": 0.02, "slide": 0.012}   # free space before contact (m)
CONTACT_HEIGHT = 0.018       # fingertip height while pushing (m above the table; cube top at 0.05)
APPROACH_HEIGHT = 0.09       # fingertip height above the contact point, before descending (m)
LIFT = 0.06                  # how far the hand rises after the push (m), clearing the cube tops
RETREAT = 0.4                # then it moves this share of the way back towards the start (xy), rising,
                             # and from there back to the start
ARC = 0.04                   # the reach to the cube bulges up by this much (m), clearing the other cube
#: Share of the steps spent on each segment: reach above, descend, move the cube, lift, back over
#: the cubes, home, rest there.
PHASES = (0.27, 0.13, 0.32, 0.05, 0.06, 0.11, 0.06)

# Check thresholds (defaults of SimConfig): the cube must move at least MIN_MOVE along
# the direction, sideways at most MAX_OFF_AXIS_RATIO of that, and the other cube less
# than MAX_OTHER_MOVE.
MIN_MOVE = 0.04
MAX_OFF_AXIS_RATIO = 0.5
MAX_OTHER_MOVE = 0.01


@dataclass(frozen=True)
class Variation:
    """The random part of one execution (drawn by :func:`sample_variation`)."""

    distance: float = 0.09                    # how far the cube should move (m)
    contact_height: float = CONTACT_HEIGHT    # fingertip height during the move (m)
    lateral: float = 0.0                      # contact point shifted across the direction (m)
    approach_height: float = APPROACH_HEIGHT  # fingertip height above the contact point (m)
    phases: tuple[float, ...] = PHASES


def sample_variation(rng: np.random.Generator, distance: tuple[float, float] = (0.085, 0.095),
                     lateral: float = 0.006, height: float = 0.004, timing: float = 0.02) -> Variation:
    """Draw the small random differences between recordings of one pattern.

    ``distance`` is a (low, high) range in metres; ``lateral`` and ``height``
    are half-widths (m) of uniform offsets; ``timing`` scales each phase's
    share by a factor in [1 - timing, 1 + timing].
    """
    phases = np.array(PHASES) * rng.uniform(1 - timing, 1 + timing, size=len(PHASES))
    return Variation(distance=float(rng.uniform(*distance)),
                     contact_height=float(CONTACT_HEIGHT + rng.uniform(-height, height)),
                     lateral=float(rng.uniform(-lateral, lateral)),
                     approach_height=float(APPROACH_HEIGHT + rng.uniform(-0.01, 0.01)),
                     phases=tuple(float(x) for x in phases / phases.sum()))


def direction(action: str, cube_xy: np.ndarray, other_xy: np.ndarray) -> np.ndarray:
    """Unit direction (2,) in the agent's frame: push +x, pull -x, slide away from the other cube."""
    if action == "push":
        return np.array([1.0, 0.0])
    if action == "pull":
        return np.array([-1.0, 0.0])
    if action == "slide":
        return np.array([0.0, 1.0 if cube_xy[1] > other_xy[1] else -1.0])
    raise ValueError(f"unknown action {action!r}; the actions are: {', '.join(ACTIONS)}")


def world_direction(robot: Robot, action: str, cube: np.ndarray, other: np.ndarray) -> np.ndarray:
    """:func:`direction` for ``robot``, turned into the world frame (2,); cube centres in world metres."""
    d = direction(action, robot.to_robot(cube)[:2], robot.to_robot(other)[:2])
    return (robot.to_world(np.array([*d, 0.0])) - robot.to_world(np.zeros(3)))[:2]   # rotate only


def min_jerk(tau: np.ndarray) -> np.ndarray:
    """Minimum-jerk profile s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 for tau in [0, 1]."""
    return tau ** 3 * (10.0 - 15.0 * tau + 6.0 * tau ** 2)


def hand_waypoints(action: str, cube: np.ndarray, other: np.ndarray, home: np.ndarray,
                   variation: Variation = Variation()) -> np.ndarray:
    """The eight hand waypoints (8, 3) in the agent's frame, for cube centres ``cube``, ``other`` (3,).

    The last two are both the start position: the last segment is a rest.
    """
    d = direction(action, cube[:2], other[:2])
    across = np.array([-d[1], d[0]])                            # d turned by 90 degrees
    offset = CONTACT_OFFSET[action]
    contact_xy = cube[:2] - d * (offset + APPROACH_GAP[action]) + across * variation.lateral
    end_xy = cube[:2] + d * (variation.distance - offset) + across * variation.lateral
    z = variation.contact_height
    return np.array([
        home,
        [*contact_xy, variation.approach_height],               # above the contact point
        [*contact_xy, z],                                       # beside the cube
        [*end_xy, z],                                           # the cube has moved
        [*end_xy, z + LIFT],                                    # lifted off the cube
        [*(end_xy + RETREAT * (home[:2] - end_xy)), z + LIFT + 0.02],   # on the way back, still rising
        home,                                                   # back at the start: both cubes in view
        home,                                                   # and rest there
    ])


def hand_path(waypoints: np.ndarray, steps: int, phases: tuple[float, ...] = PHASES,
              arc: float = ARC) -> np.ndarray:
    """Hand positions (steps, 3): min-jerk segments between consecutive waypoints.

    Step 0 is the first waypoint, the last step the last one; segment k gets
    a ``phases[k]`` share of the steps. The first segment (the reach) rises
    by up to ``arc`` metres in its middle: z += arc · sin(pi · s).
    """
    bounds = np.concatenate([[0.0], np.cumsum(phases)]) / np.sum(phases)   # segment limits in [0, 1]
    t = np.linspace(0.0, 1.0, steps)
    seg = np.clip(np.searchsorted(bounds, t, side="right") - 1, 0, len(phases) - 1)
    tau = (t - bounds[seg]) / (bounds[seg + 1] - bounds[seg])            # time within the segment
    s = min_jerk(np.clip(tau, 0.0, 1.0))[:, None]
    path = waypoints[seg] + s * (waypoints[seg + 1] - waypoints[seg])   # (steps, 3)
    path[:, 2] += arc * np.sin(np.pi * s[:, 0]) * (seg == 0)            # first segment: an arc over the cubes
    return path


@dataclass
class Plan:
    """What an agent intends: ``hand`` (T, 3) world path and ``joints`` (T, 5) radians."""

    action: str
    direction: np.ndarray      # (2,) unit vector, world frame
    hand: np.ndarray
    joints: np.ndarray


def plan_action(robot: Robot, action: str, cube: np.ndarray, other: np.ndarray, steps: int,
                variation: Variation = Variation(), ik_every: int = 4) -> Plan:
    """Plan ``action`` on the cube at world position ``cube`` (3,) for ``robot``, in ``steps`` steps.

    IK runs at every ``ik_every``-th step of the hand path (and the last one),
    each solve seeded with the previous one; the joints in between are linear
    interpolations (an IK solve costs ~0.5 ms, a frame's budget is a few ms).
    """
    home = robot.to_robot(robot.forward_kinematics(np.array(HOME_POSE)))
    cube_local, other_local = robot.to_robot(cube), robot.to_robot(other)
    local = hand_waypoints(action, cube_local, other_local, home, variation)
    path = robot.to_world(hand_path(local, steps, variation.phases))     # (T, 3) world
    knots = sorted(set(range(0, steps, ik_every)) | {steps - 1})         # steps that get an IK solve
    q = np.array(HOME_POSE)
    solved = [q]
    for t in knots[1:]:
        q = robot.inverse_kinematics(path[t], seed=q)                  # seeded with the previous knot
        solved.append(q)
    solved = np.array(solved)                                           # (K, 5)
    joints = np.stack([np.interp(np.arange(steps), knots, solved[:, j]) for j in range(solved.shape[1])],
                      axis=1)                                           # (T, 5)
    robot.reset(joints[0])                                              # back to the start pose
    d_world = world_direction(robot, action, cube, other)
    return Plan(action, d_world, path, joints)


@dataclass
class ActionCheck:
    """Did the cube move the way the words say? Distances in metres."""

    passed: bool
    along: float          # target cube's displacement along the action's direction
    off_axis: float       # ... across it (absolute)
    other: float          # how far the other cube moved
    reason: str           # "" when passed, else what went wrong


def check_action(direction_xy: np.ndarray, target: np.ndarray, other: np.ndarray,
                 min_move: float = MIN_MOVE, max_off_axis_ratio: float = MAX_OFF_AXIS_RATIO,
                 max_other_move: float = MAX_OTHER_MOVE) -> ActionCheck:
    """Check cube displacements (3,) ``target`` and ``other`` against the direction (2,) (world frame)."""
    along = float(target[:2] @ direction_xy)                       # projection on the direction
    off = float(np.linalg.norm(target[:2] - along * direction_xy))  # what is left is sideways
    other_moved = float(np.linalg.norm(other))
    reasons = []
    if along < min_move:
        reasons.append(f"moved {along * 100:.1f} cm along the direction (< {min_move * 100:.1f} cm)")
    if off > max_off_axis_ratio * max(along, 0.0):
        reasons.append(f"moved {off * 100:.1f} cm sideways (> {max_off_axis_ratio:.2f} x along)")
    if other_moved >= max_other_move:
        reasons.append(f"the other cube moved {other_moved * 100:.1f} cm (>= {max_other_move * 100:.1f} cm)")
    return ActionCheck(not reasons, along, off, other_moved, "; ".join(reasons))
