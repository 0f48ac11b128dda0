"""pgae_lite.sim: the robot, the scene, the 12 actions, recording and determinism.

Fast on purpose: actions are checked without rendering (physics only), and
only a few fast (50-step) episodes are recorded with both views.
"""
from __future__ import annotations

import math

import numpy as np
import pybullet as p
import pytest
from pybullet_utils import bullet_client

from pgae_lite.sim import (
    CUBE_RGBA,
    HOME_POSE,
    JOINT_LIMITS,
    JOINT_NAMES,
    Robot,
    Scene,
    SceneLayout,
    SimConfig,
    Simulation,
    check_action,
    episode_seed,
    execute_trajectory,
    record_episode,
)
from pgae_lite.sim.robot import REST_POSE
from pgae_lite.world.patterns import ACTION_SIDES, ARRANGEMENTS, Pattern, pattern_number
from pgae_lite.world.words import COLOURS

FAST = pattern_number(1, 0, 0)   # pattern numbers from 72 on are the fast (50-step) ones


@pytest.fixture(scope="module")
def client():
    c = bullet_client.BulletClient(connection_mode=p.DIRECT)
    yield c
    c.disconnect()


@pytest.fixture(scope="module")
def sim():
    return Simulation(SimConfig())


@pytest.fixture(scope="module")
def episode():
    """One fast episode with both views: pattern 72 = push red (left cube) fast, red+blue."""
    return record_episode(FAST, 0)


def colour_pixels(image: np.ndarray, colour: str) -> int:
    """Pixels whose colour direction is that of a cube colour (shading scales brightness only)."""
    rgb = image.reshape(-1, 3).astype(float)
    ref = np.array(CUBE_RGBA[colour][:3])
    cos = rgb @ ref / (np.linalg.norm(rgb, axis=1) * np.linalg.norm(ref) + 1e-9)
    return int(((cos > 0.995) & (rgb.max(1) > 60)).sum())


# --------------------------------------------------------------------------- robot
def test_robot_has_five_named_revolute_joints_within_limits(client):
    client.resetSimulation()
    robot = Robot(client)
    info = {client.getJointInfo(robot.id, j)[1].decode(): client.getJointInfo(robot.id, j)
            for j in range(client.getNumJoints(robot.id))}
    revolute = [n for n, i in info.items() if i[2] == p.JOINT_REVOLUTE]
    assert tuple(revolute) == JOINT_NAMES and len(JOINT_NAMES) == 5
    for name, (lo, hi) in zip(JOINT_NAMES, JOINT_LIMITS):
        assert info[name][8:10] == (lo, hi) and lo < hi
    for pose in (HOME_POSE, REST_POSE):
        assert all(lo <= q <= hi for q, (lo, hi) in zip(pose, JOINT_LIMITS))
    np.testing.assert_allclose(robot.joint_positions(), HOME_POSE, atol=1e-9)


def test_joint_signs_are_the_documented_ones(client):
    """Positive shoulder_y raises the arm forward, positive arm_x lifts it outward (+y), ..."""
    client.resetSimulation()
    robot = Robot(client)
    zero = robot.forward_kinematics(np.zeros(5))
    assert zero[2] < 0.0                                          # the arm hangs down in the zero pose
    assert robot.forward_kinematics(np.array([0, 0.5, 0, 0, 0]))[0] > zero[0] + 0.05
    assert robot.forward_kinematics(np.array([0, 0, 0.5, 0, 0]))[1] > zero[1] + 0.05
    bent = robot.forward_kinematics(np.array([0, 0, 0, 1.0, 0]))
    assert bent[0] > zero[0] + 0.05 and bent[2] > zero[2] + 0.05  # the forearm swings forward and up
    raised = np.array([0, 1.5, 0, 0, 0])
    assert robot.forward_kinematics(raised + [0.5, 0, 0, 0, 0])[1] > robot.forward_kinematics(raised)[1] + 0.05
    home = robot.forward_kinematics(np.array(HOME_POSE))
    assert 0.03 < home[2] < 0.12                                  # start pose: hand above the table


def test_ik_reaches_reachable_targets(client):
    client.resetSimulation()
    robot = Robot(client)
    for target in ([0.19, 0.08, 0.02], [0.22, -0.05, 0.03], [0.12, 0.0, 0.05], [0.17, -0.12, 0.04]):
        q = robot.inverse_kinematics(np.array(target))
        assert all(lo - 1e-9 <= v <= hi + 1e-9 for v, (lo, hi) in zip(q, JOINT_LIMITS))
        assert np.linalg.norm(robot.forward_kinematics(q) - target) < 0.01, target


def test_second_robot_faces_the_first(client):
    client.resetSimulation()
    other = Robot(client, base_xyz=(0.38, 0.0, 0.0), base_yaw=math.pi)
    hand = other.hand_position()
    assert hand[0] < 0.38 and hand[1] < 0.0          # its left arm reaches towards NICO, on NICO's right
    np.testing.assert_allclose(other.to_robot(other.to_world(np.array([0.1, 0.2, 0.3]))), [0.1, 0.2, 0.3])


# --------------------------------------------------------------------------- scene
def test_scene_has_two_cubes_of_the_requested_colours():
    assert set(CUBE_RGBA) == set(COLOURS)
    scene = Scene(SceneLayout("yellow", "violet"))
    try:
        colours = [scene.client.getVisualShapeData(b)[0][7] for b in scene.cubes]
        np.testing.assert_allclose(colours, [CUBE_RGBA["yellow"], CUBE_RGBA["violet"]], atol=1e-6)
        left, right = scene.cube_positions()
        assert left[1] > 0.04 and right[1] < -0.04 and abs(left[2] - 0.025) < 1e-3   # NICO's left is +y
        image = scene.render()
        assert image.shape == (120, 160, 3) and image.dtype == np.uint8
        assert colour_pixels(image, "yellow") > 40 and colour_pixels(image, "violet") > 40
        assert colour_pixels(image, "red") < 5 and colour_pixels(image, "blue") < 5   # the check can fail
    finally:
        scene.close()
    with pytest.raises(ValueError, match="colours are: red, green"):
        SceneLayout("pink", "red")


def test_backdrop_render_equals_a_full_render(sim):
    sim.reset(FAST + 4, 0, render=False)                 # pull the right cube
    for q in sim.plan().joints[:30]:                     # arm in the middle of the action
        frame = sim.step(q)
    np.testing.assert_array_equal(frame, sim.scene.render_full())


# --------------------------------------------------------------------------- the 12 actions
@pytest.mark.parametrize("number", [pattern_number(s, 0, a) for s in (0, 1) for a in range(6)],
                         ids=lambda n: Pattern.from_number(n).code)
def test_each_action_moves_the_named_cube_the_named_way(sim, number):
    pattern = Pattern.from_number(number)
    sim.reset(number, 0, render=False)
    ex = sim.run(sim.plan().joints, render=False)
    i = 0 if pattern.side == "L" else 1
    moved, other = ex.displacement[i], ex.displacement[1 - i]
    expected = {"push": (0, 1.0), "pull": (0, -1.0), "slide": (1, 1.0 if pattern.side == "L" else -1.0)}
    axis, sign = expected[pattern.action]                  # world frame = NICO's frame: +x away, +y left
    assert sign * moved[axis] > 0.04, ex.displacement
    assert abs(moved[1 - axis]) < 0.5 * abs(moved[axis])
    assert np.linalg.norm(other) < 0.01
    assert ex.passed and ex.measured.shape == (pattern.steps, 5)
    assert np.abs(ex.tracking_error).max() < 0.5           # no arm jammed against the table


def test_arrangements_and_actions_follow_the_patterns_module():
    assert Pattern.from_number(0).left == ARRANGEMENTS[0][0] and ACTION_SIDES[2] == ("slide", "L")


# --------------------------------------------------------------------------- episodes
def test_episode_shapes_and_opposite_agent(episode):
    assert (episode.pattern, episode.variation, episode.valid) == (FAST, 0, True)
    assert episode.joints.shape == (50, 5) and episode.joints.dtype == np.float32
    assert episode.images.shape == episode.images_opposite.shape == (50, 120, 160, 3)
    assert episode.images.dtype == np.uint8 and episode.displacement.shape == (2, 3)
    assert episode.seed == episode_seed(FAST, 0, 0, episode.attempts - 1)
    assert episode.displacement[0, 0] > 0.04                     # NICO pushed red away from itself
    opposite = episode.info["displacement_opposite"]
    assert opposite[0, 0] < -0.04 and np.linalg.norm(opposite[1]) < 0.01   # the other agent pushed it to NICO
    assert episode.info["check_opposite"].passed
    assert not np.array_equal(episode.images[-1], episode.images_opposite[-1])
    assert colour_pixels(episode.images[0], "red") > 40 and colour_pixels(episode.images[0], "blue") > 40


def test_same_arguments_give_identical_episodes(episode):
    record_episode(FAST + 5, 1)                                   # another episode in between
    again = record_episode(FAST, 0)
    for name in ("joints", "images", "images_opposite", "displacement"):
        assert getattr(again, name).tobytes() == getattr(episode, name).tobytes(), name
    assert again.seed == episode.seed


def test_variations_differ(episode):
    other = record_episode(FAST, 1)
    assert not np.array_equal(other.joints, episode.joints)


def test_execute_trajectory_checks_any_trajectory(sim, episode):
    still = np.tile(np.array(HOME_POSE), (50, 1))
    ex = execute_trajectory(still, FAST, 0, render=False)
    assert not ex.passed and "along the direction" in ex.check.reason    # nothing moved: the check fails
    sim.reset(FAST, 0, render=False)
    plan = sim.plan()
    ex = execute_trajectory(plan.joints, FAST, 0)
    assert ex.passed and ex.frames.shape == (50, 120, 160, 3)
    assert (ex.pattern, ex.variation, ex.description) == (FAST, 0, "")
    assert np.array_equal(ex.joints, plan.joints) and np.array_equal(ex.targets, plan.joints)   # asked = sent
    np.testing.assert_array_equal(ex.tracking_error, ex.measured - ex.targets)
    with pytest.raises(ValueError, match=r"shape \(T, 5\)"):
        execute_trajectory(np.zeros((50, 4)), FAST)


def test_check_action_reports_what_went_wrong():
    d = np.array([1.0, 0.0])
    assert check_action(d, np.array([0.08, 0.01, 0]), np.zeros(3)).passed
    assert "along" in check_action(d, np.array([0.02, 0.0, 0]), np.zeros(3)).reason
    assert "sideways" in check_action(d, np.array([0.05, 0.04, 0]), np.zeros(3)).reason
    assert "other cube" in check_action(d, np.array([0.08, 0.0, 0]), np.array([0.0, 0.02, 0])).reason
    assert not check_action(-d, np.array([0.08, 0.0, 0]), np.zeros(3)).passed     # wrong way


def test_bad_arguments_raise_clear_errors():
    for bad in (-1, 144, 3.5):
        with pytest.raises(ValueError, match="0-143"):
            record_episode(bad, 0)
    with pytest.raises(ValueError, match="variation"):
        record_episode(0, -1)
    with pytest.raises(ValueError, match="agents are: nico, opposite"):
        Simulation().reset(0, agent="human")


def test_gives_up_after_max_attempts():
    impossible = SimConfig(min_move=0.5, max_attempts=2)           # no push moves a cube 50 cm
    with pytest.raises(RuntimeError, match="no valid episode in 2 attempts"):
        record_episode(FAST, 0, impossible)
