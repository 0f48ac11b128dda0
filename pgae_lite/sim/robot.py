"""A NICO-like robot: torso, head with an eye camera, a 5-joint left arm and a hand.

Paper, Sec. 4 (Dataset): NICO moves cubes with its left arm; the data holds
the 5 joint angles of that arm. The real NICO's URDF and the authors' Blender
scene are not public, so we generate a small robot of the same kind from
Python as URDF text, built from boxes (cylinders optional, see ``LIMB_SHAPE``)
so that pybullet's TinyRenderer draws it fast.

Frames and units: metres and radians. The robot's own frame has its origin on
the table-top plane below the middle of its shoulders; +x points forward (to
the table), +y to the robot's LEFT, +z up. In the zero pose the left arm hangs
straight down. Joint axes are given in that zero pose, and signs are chosen
so that positive angles are the natural motion:

=============  ======  ==========================================  ==============
joint          axis    positive angle                              limits (rad)
=============  ======  ==========================================  ==============
l_shoulder_z   +z      swing the raised arm to the left (outward)  -1.30 .. 1.30
l_shoulder_y   -y      raise the arm forward                       -0.50 .. 2.50
l_arm_x        +x      lift the arm sideways, away from the body   -0.40 .. 1.60
l_elbow_y      -y      bend the forearm forward / up               0.00 .. 2.40
l_wrist_y      -y      bend the hand up (negative: hand down)      -1.60 .. 1.00
=============  ======  ==========================================  ==============

Deviation from NICO: the real arm has six joints (its wrist turns about z and
bends about x in NICO's own frames); we keep one wrist flexion joint, named
after its axis in our zero pose, so that the arm has the paper's 5 joints.
"""
from __future__ import annotations

import functools
import math
import os
import tempfile
from dataclasses import dataclass

import numpy as np
import pybullet as p
from pybullet_utils import bullet_client

from pgae_lite.util.storage import atomic_write_text, config_digest

#: The 5 recorded joints of the left arm, from shoulder to wrist.
JOINT_NAMES: tuple[str, ...] = ("l_shoulder_z", "l_shoulder_y", "l_arm_x", "l_elbow_y", "l_wrist_y")
#: Joint limits (lower, upper) in radians, in the order of JOINT_NAMES.
JOINT_LIMITS: tuple[tuple[float, float], ...] = (
    (-1.30, 1.30), (-0.50, 2.50), (-0.40, 1.60), (0.00, 2.40), (-1.60, 1.00))
#: The pose every action starts from: elbow bent, hand 6 cm above the table, left of and nearer than the cubes.
HOME_POSE: tuple[float, ...] = (0.30, 0.00, 0.50, 1.95, -1.55)
#: IK's rest pose (its null space pulls towards it): elbow bent, wrist flexed down.
REST_POSE: tuple[float, ...] = (0.0, 0.50, 0.50, 1.40, -1.30)

# Body dimensions (metres), NICO-like proportions (a child-size humanoid).
SHOULDER = (-0.02, 0.105, 0.22)       # left shoulder joint in the robot frame
UPPER_ARM, FOREARM, HAND = 0.18, 0.17, 0.075
LIMB_RADIUS = 0.022                   # half the thickness of upper arm and forearm
# Limbs as boxes: TinyRenderer draws a cylinder as many thin triangles, which made
# a frame ~1 ms slower (and each robot ~4 ms slower to load). Set "cylinder" for rounder limbs.
LIMB_SHAPE = "box"
HAND_SIZE = (0.025, 0.045, HAND)       # thickness (x), width (y), length (z, along the hand)
FINGERTIP = HAND - 0.012              # IK point: near the end of the hand, on its axis
EYE = (0.035, 0.03, 0.385)            # left eye camera, robot frame
EYE_PITCH = 0.90                      # camera looks down by this angle (rad, ~52 degrees)
TORSO = ((0.11, 0.17, 0.30), (-0.04, 0, 0.03))   # the torso's box: size (x, y, z) and centre, robot frame

WHITE = (0.92, 0.92, 0.90, 1.0)       # NICO's shell
GREY = (0.45, 0.46, 0.50, 1.0)        # joints and torso
DARK = (0.18, 0.18, 0.20, 1.0)        # hand and eyes


# --------------------------------------------------------------------------- URDF text
def _inertia_box(m: float, x: float, y: float, z: float) -> str:
    # solid box: Ixx = m (y² + z²) / 12, ...
    return (f'<inertia ixx="{m * (y * y + z * z) / 12:.6g}" iyy="{m * (x * x + z * z) / 12:.6g}" '
            f'izz="{m * (x * x + y * y) / 12:.6g}" ixy="0" ixz="0" iyz="0"/>')


def _geometry(shape: str, size: tuple[float, ...]) -> str:
    if shape == "box":
        return f'<box size="{size[0]} {size[1]} {size[2]}"/>'
    return f'<cylinder radius="{size[0]}" length="{size[1]}"/>'


def _link(name: str, mass: float, shape: str | None = None, size: tuple = (), xyz: tuple = (0, 0, 0),
          rgba: tuple = WHITE, collide: bool = False) -> str:
    """One link with at most one shape (``box`` size = (x, y, z), ``cylinder`` size = (radius, length)).

    One shape per link keeps colours per link, which the renderer relies on.
    """
    box = size if shape == "box" else (2 * size[0], 2 * size[0], size[1]) if shape else (0.01,) * 3
    o = f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}"/>'
    xml = f'<link name="{name}"><inertial>{o}<mass value="{mass}"/>{_inertia_box(mass, *box)}</inertial>'
    if shape:
        xml += (f'<visual>{o}<geometry>{_geometry(shape, size)}</geometry><material name="{name}">'
                f'<color rgba="{" ".join(map(str, rgba))}"/></material></visual>')
    if shape and collide:
        xml += f'<collision>{o}<geometry>{_geometry(shape, size)}</geometry></collision>'
    return xml + "</link>"


def _joint(name: str, parent: str, child: str, xyz: tuple = (0, 0, 0), axis: tuple = (0, 0, 1),
           limits: tuple[float, float] | None = None, rpy: tuple = (0, 0, 0)) -> str:
    """A revolute joint (``limits`` given) or a fixed one."""
    kind = "fixed" if limits is None else "revolute"
    xml = (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
           f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/>')
    if limits is not None:
        xml += (f'<axis xyz="{axis[0]} {axis[1]} {axis[2]}"/>'
                f'<limit lower="{limits[0]}" upper="{limits[1]}" effort="20" velocity="8"/>')
    return xml + "</joint>"


def _limb(radius: float, length: float) -> tuple[str, tuple[float, ...]]:
    """Shape and size of a limb of the given half-thickness and length, along z."""
    return ("cylinder", (radius, length)) if LIMB_SHAPE == "cylinder" else ("box", (2 * radius, 2 * radius, length))


def nico_urdf() -> str:
    """The robot as URDF text (one string; pybullet reads it from a file)."""
    sx, sy, sz = SHOULDER
    arm = UPPER_ARM + FOREARM
    # the body: still parts, each a link fixed to the torso (name, shape, size, centre, colour)
    body = [("neck", *_limb(0.022, 0.10), (-0.03, 0, 0.22), GREY),
            ("head", "box", (0.13, 0.12, 0.12), (-0.03, 0, 0.33), WHITE),
            ("l_eye", "box", (0.012, 0.022, 0.022), (EYE[0] - 0.006, EYE[1], EYE[2]), DARK),
            ("r_eye", "box", (0.012, 0.022, 0.022), (EYE[0] - 0.006, -EYE[1], EYE[2]), DARK),
            ("l_shoulder_cap", "box", (0.06, 0.05, 0.05), (sx, sy - 0.01, sz), GREY),
            ("r_shoulder_cap", "box", (0.06, 0.05, 0.05), (sx, -sy + 0.01, sz), GREY),
            ("r_arm", *_limb(LIMB_RADIUS, arm), (sx, -sy, sz - arm / 2), WHITE)]   # hangs still
    links = [_link("torso", 0.0, "box", *TORSO, WHITE)]
    joints = []
    for name, shape, size, xyz, rgba in body:
        links.append(_link(name, 0.01, shape, size, (0, 0, 0), rgba))
        joints.append(_joint(f"{name}_joint", "torso", name, xyz))
    links += [
        _link("eye_camera", 0.001),
        _link("l_shoulder_link", 0.05),
        _link("l_upper_arm_base", 0.05),
        _link("l_upper_arm", 0.20, *_limb(LIMB_RADIUS, UPPER_ARM), (0, 0, -UPPER_ARM / 2), WHITE, True),
        _link("l_elbow", 0.02, *_limb(LIMB_RADIUS * 1.05, 0.05), (0, 0, 0), GREY),
        _link("l_forearm", 0.15, *_limb(LIMB_RADIUS * 0.9, FOREARM), (0, 0, -FOREARM / 2), WHITE, True),
        _link("l_hand", 0.08, "box", HAND_SIZE, (0, 0, -HAND / 2), DARK, True),
        _link("l_fingertip", 0.001),
    ]
    joints += [
        # the camera looks along its link's +x axis, pitched down by EYE_PITCH
        _joint("eye_camera_joint", "torso", "eye_camera", EYE, rpy=(0, EYE_PITCH, 0)),
        _joint("l_shoulder_z", "torso", "l_shoulder_link", SHOULDER, (0, 0, 1), JOINT_LIMITS[0]),
        _joint("l_shoulder_y", "l_shoulder_link", "l_upper_arm_base", (0, 0, 0), (0, -1, 0), JOINT_LIMITS[1]),
        _joint("l_arm_x", "l_upper_arm_base", "l_upper_arm", (0, 0, 0), (1, 0, 0), JOINT_LIMITS[2]),
        _joint("l_elbow_y", "l_upper_arm", "l_forearm", (0, 0, -UPPER_ARM), (0, -1, 0), JOINT_LIMITS[3]),
        # a grey cap on the elbow, across the joint axis (rpy turns its z axis onto y)
        _joint("l_elbow_cap_joint", "l_forearm", "l_elbow", rpy=(1.5708, 0, 0)),
        _joint("l_wrist_y", "l_forearm", "l_hand", (0, 0, -FOREARM), (0, -1, 0), JOINT_LIMITS[4]),
        _joint("l_fingertip_joint", "l_hand", "l_fingertip", (0, 0, -FINGERTIP)),
    ]
    return f'<?xml version="1.0"?><robot name="nico_lite">{"".join(links)}{"".join(joints)}</robot>'


@functools.lru_cache(maxsize=1)
def urdf_path() -> str:
    """Path of a file holding :func:`nico_urdf` (written once; named by its content's digest)."""
    text = nico_urdf()
    path = os.path.join(tempfile.gettempdir(), f"nico_lite_{config_digest(text)}.urdf")
    if not os.path.exists(path):
        atomic_write_text(path, text)          # parallel workers never see half a file
    return path


# --------------------------------------------------------------------------- the robot in a world
@dataclass
class Robot:
    """One NICO-like robot loaded into a pybullet world (a ``BulletClient``).

    ``base_xyz`` / ``base_yaw`` place the robot frame in the world (yaw in
    radians about z): a second robot at ``yaw = pi`` across the table faces
    the first one. After loading, the arm is at :data:`HOME_POSE`.
    Attributes: ``id`` (pybullet body), ``joint_ids`` (the 5 arm joints),
    ``fingertip_link`` (the point IK steers), ``hand_link``, ``eye_link``,
    ``arm_links`` (all links that move with the arm).
    """

    client: bullet_client.BulletClient
    base_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    base_yaw: float = 0.0
    max_force: float = 12.0            # N·m per joint motor

    def __post_init__(self) -> None:
        c = self.client
        self.base_orientation = c.getQuaternionFromEuler((0.0, 0.0, self.base_yaw))
        self.id = c.loadURDF(urdf_path(), self.base_xyz, self.base_orientation, useFixedBase=True)
        names = {c.getJointInfo(self.id, j)[1].decode(): j for j in range(c.getNumJoints(self.id))}
        self.joint_ids = [names[n] for n in JOINT_NAMES]
        self.fingertip_link = names["l_fingertip_joint"]       # a link's index is its parent joint's
        self.hand_link = names["l_wrist_y"]
        self.eye_link = names["eye_camera_joint"]
        self.arm_links = [names[n] for n in ("l_arm_x", "l_elbow_y", "l_elbow_cap_joint", "l_wrist_y")]
        self.lower = np.array([lo for lo, _ in JOINT_LIMITS])
        self.upper = np.array([hi for _, hi in JOINT_LIMITS])
        self.reset(HOME_POSE)

    # ---- joints
    def reset(self, q: tuple[float, ...] | np.ndarray) -> None:
        """Teleport the arm to joint angles ``q`` (5,) and hold them there (no physics)."""
        self._set_joints(q)
        self.set_targets(q)

    def set_targets(self, q: tuple[float, ...] | np.ndarray) -> None:
        """Position control: the joint motors drive towards ``q`` (5,) radians during the next steps."""
        self.client.setJointMotorControlArray(
            self.id, self.joint_ids, p.POSITION_CONTROL, targetPositions=[float(v) for v in q],
            forces=[self.max_force] * len(self.joint_ids))

    def joint_positions(self) -> np.ndarray:
        """Measured joint angles (5,) in radians."""
        return np.array([s[0] for s in self.client.getJointStates(self.id, self.joint_ids)])

    # ---- Cartesian
    def hand_position(self) -> np.ndarray:
        """World position (3,) of the fingertip point, the point IK steers."""
        state = self.client.getLinkState(self.id, self.fingertip_link, computeForwardKinematics=True)
        return np.array(state[4])                      # [4]: the link frame's world position

    def to_world(self, xyz_robot: np.ndarray) -> np.ndarray:
        """Robot-frame point(s) (..., 3) -> world frame: rotate by base_yaw, then shift by base_xyz."""
        c, s = math.cos(self.base_yaw), math.sin(self.base_yaw)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return np.asarray(xyz_robot) @ rot.T + np.asarray(self.base_xyz)

    def to_robot(self, xyz_world: np.ndarray) -> np.ndarray:
        """World point(s) (..., 3) -> robot frame (the inverse of :meth:`to_world`)."""
        c, s = math.cos(self.base_yaw), math.sin(self.base_yaw)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return (np.asarray(xyz_world) - np.asarray(self.base_xyz)) @ rot

    def inverse_kinematics(self, target_world: np.ndarray, seed: np.ndarray | None = None,
                           tolerance: float = 0.004, max_rounds: int = 4) -> np.ndarray:
        """Joint angles (5,) that put the fingertip at ``target_world`` (3,), within ``tolerance`` m if it can.

        Position-only damped least squares (pybullet's ``calculateInverseKinematics``,
        40 iterations a round) with the joint limits, and a null space pulling
        towards :data:`REST_POSE` so the wrist stays flexed down. It starts from
        ``seed`` (default: the current joint angles) and runs up to ``max_rounds``
        rounds, each from the previous result, until the fingertip is within
        ``tolerance``; the null space keeps a few mm of error. The arm's state
        is restored afterwards. Asking for position and orientation with 5
        joints fails quietly (BRIEF §3), so we do not.
        """
        keep = self._joint_state()
        q = keep[0] if seed is None else np.asarray(seed, dtype=np.float64)
        for _ in range(max_rounds):
            self._set_joints(q)                        # pybullet's IK starts from the current state
            q = np.array(self.client.calculateInverseKinematics(
                self.id, self.fingertip_link, [float(v) for v in target_world],
                lowerLimits=list(self.lower), upperLimits=list(self.upper),
                jointRanges=list(self.upper - self.lower), restPoses=list(REST_POSE),
                maxNumIterations=40, residualThreshold=1e-4)[:len(JOINT_NAMES)])
            q = np.clip(q, self.lower, self.upper)
            self._set_joints(q)
            if np.linalg.norm(self.hand_position() - target_world) < tolerance:
                break
        self._set_joints(*keep)
        return q

    def forward_kinematics(self, q: np.ndarray) -> np.ndarray:
        """Fingertip world position (3,) at joint angles ``q``; the arm's state is restored."""
        keep = self._joint_state()
        self._set_joints(q)
        xyz = self.hand_position()
        self._set_joints(*keep)
        return xyz

    def _joint_state(self) -> tuple[np.ndarray, np.ndarray]:
        states = self.client.getJointStates(self.id, self.joint_ids)
        return np.array([s[0] for s in states]), np.array([s[1] for s in states])   # angles, velocities

    def _set_joints(self, q: np.ndarray, velocities: np.ndarray | None = None) -> None:
        """Teleport the joints (motors unchanged); for IK, FK and resets."""
        qd = np.zeros(len(q)) if velocities is None else velocities
        for j, v, w in zip(self.joint_ids, q, qd):
            self.client.resetJointState(self.id, j, float(v), float(w))

    def eye_pose(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Eye camera position, viewing direction and up vector (world frame, each (3,))."""
        pos, orn = self.client.getLinkState(self.id, self.eye_link, computeForwardKinematics=True)[4:6]
        m = np.array(self.client.getMatrixFromQuaternion(orn)).reshape(3, 3)
        return np.array(pos), m[:, 0], m[:, 2]       # link x axis: forward; z axis: up
