"""The tabletop world: a table, two coloured 5 cm cubes, NICO and its eye camera.

Paper, Sec. 4 (Dataset) and Fig. 1: NICO sits at a table with two cubes of
different colours, one on its left and one on its right; a second agent sits
across the table. Our world, in metres (world frame = NICO's robot frame):

- NICO's base at the origin facing +x; +y is NICO's LEFT, z = 0 is the table top.
- The table top spans x in [0.03, 0.35] and y in [-0.35, 0.35]; no legs and
  no ground plane (the eye never sees them, and pixels cost render time).
- The cubes rest at x = ``TABLE_CENTRE_X`` (+ a little noise), y = +0.08 (left
  cube) and -0.08 (right cube).
- The opposite agent is the same robot at x = 2 · ``TABLE_CENTRE_X``, turned
  by 180 degrees: its left is NICO's right. Both robots are always there;
  one of them (the *actor*) moves, the other sits still at its start pose.

:meth:`Scene.render` draws NICO's eye view with pybullet's TinyRenderer (CPU,
no EGL, no shadows). TinyRenderer's cost follows the number of pixels it
fills (0.2-0.5 µs each on a laptop core: ~6 ms for a full 160 x 120 frame of
this scene), and most pixels show things that never move: the table, the
robots' bodies. So the scene renders those once per world into a *backdrop*
(colour + depth), and each frame renders only the moving parts (the cubes
and the acting arm) and merges the two by depth, pixel by pixel, as a
z-buffer does:

    pixel = moving[pixel] if depth_moving[pixel] < depth_backdrop[pixel] else backdrop[pixel]

The result equals a full render (a test checks it) in ~1.5 ms instead of ~6.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet as p
from pybullet_utils import bullet_client

from pgae_lite.sim._quiet import silenced
from pgae_lite.sim.robot import Robot
from pgae_lite.world.colours import CUBE_RGBA, TABLE_RGBA

CUBE_SIZE = 0.05                          # edge length (m)
CUBE_MASS = 0.08                          # kg (a hollow wooden toy block)
CUBE_Y = 0.08                             # |y| of the cube centres (left +, right -)
TABLE_CENTRE_X = 0.19                     # x of the cube centres; the opposite agent sits at 2x this
TABLE_X = (0.03, 2 * TABLE_CENTRE_X - 0.03)
TABLE_HALF_WIDTH = 0.35
TABLE_THICKNESS = 0.03
# Friction coefficients; pybullet multiplies those of the two bodies in contact.
TABLE_FRICTION, CUBE_FRICTION = 1.0, 0.5  # cube on table: mu = 0.5
# the hands' friction is a Scene argument (default 0.3: hand on cube 0.15; BRIEF §3: lower helped)

IMAGE_HEIGHT, IMAGE_WIDTH = 120, 160
CAMERA_FOV_DEG = 64.0                     # vertical field of view of the eye camera
LIGHT_DIRECTION = (0.6, 0.4, 1.0)         # towards the light, world frame
BACKGROUND_RGB = (214, 222, 232)          # the wall behind the table (nothing rendered there)


def _quiet_client() -> bullet_client.BulletClient:
    """A headless pybullet world (pybullet's C code prints ``argv[0]=`` on every
    connection: silenced, so that it does not fill notebooks)."""
    with silenced(1):
        return bullet_client.BulletClient(connection_mode=p.DIRECT)


@dataclass
class SceneLayout:
    """Where the cubes are: colours and centres (world frame, metres).

    ``palette``: RGBA of colours beyond :data:`~pgae_lite.world.colours.CUBE_RGBA` (a
    :class:`pgae_lite.world.colours.World`'s ``rgba``), e.g.
    ``SceneLayout("orange", "blue", palette=world.rgba)``.
    """

    left_colour: str
    right_colour: str
    left_xy: tuple[float, float] = (TABLE_CENTRE_X, CUBE_Y)
    right_xy: tuple[float, float] = (TABLE_CENTRE_X, -CUBE_Y)
    palette: dict[str, tuple[float, float, float, float]] | None = None

    def __post_init__(self) -> None:
        colours = self.colours
        for c in (self.left_colour, self.right_colour):
            if c not in colours:
                hint = "" if self.palette else " (a new one needs palette=world.rgba)"
                raise ValueError(f"unknown cube colour {c!r}; the colours are: "
                                 f"{', '.join(colours)}{hint}")

    @property
    def colours(self) -> dict[str, tuple[float, float, float, float]]:
        """RGBA of every colour this layout may use: the six, then the palette's."""
        return {**CUBE_RGBA, **(self.palette or {})}


class Scene:
    """One pybullet world with its own physics server (several can coexist).

    ``Scene(layout)`` builds everything; :meth:`rebuild` starts over from an
    empty world (``resetSimulation``), which makes episodes bit-reproducible.
    ``actor`` is the agent whose arm moves (``"nico"`` or ``"opposite"``); the
    other agent sits still at its start pose and is drawn into the backdrop.
    ``opposite_agent=False`` leaves the second robot out.
    Attributes: ``client`` (a ``BulletClient``), ``nico`` and ``opposite``
    (:class:`~pgae_lite.sim.robot.Robot`, the latter ``None`` when absent), ``cubes`` (body ids,
    left then right), ``table``, ``actor``.
    """

    def __init__(self, layout: SceneLayout, actor: str = "nico", opposite_agent: bool = True,
                 time_step: float = 1.0 / 240.0, hand_friction: float = 0.3, solver_iterations: int = 20,
                 image_size: tuple[int, int] = (IMAGE_HEIGHT, IMAGE_WIDTH),
                 client: bullet_client.BulletClient | None = None) -> None:
        self.client = client or _quiet_client()
        self.image_size = image_size          # (height, width) pixels
        self.time_step = time_step
        self.hand_friction = hand_friction
        self.solver_iterations = solver_iterations
        self.rebuild(layout, actor, opposite_agent)

    # ---- building
    def rebuild(self, layout: SceneLayout, actor: str = "nico", opposite_agent: bool = True) -> None:
        """Empty the world and build it again for ``layout``, with ``actor`` moving."""
        if actor not in ("nico", "opposite") or (actor == "opposite" and not opposite_agent):
            raise ValueError(f"actor must be 'nico' or 'opposite' (with opposite_agent=True), got {actor!r}")
        c = self.client
        c.resetSimulation()
        c.setGravity(0.0, 0.0, -9.81)
        c.setPhysicsEngineParameter(fixedTimeStep=self.time_step, numSolverIterations=self.solver_iterations,
                                    deterministicOverlappingPairs=1)
        self.layout = layout
        self.table = self._box((TABLE_X[1] - TABLE_X[0], 2 * TABLE_HALF_WIDTH, TABLE_THICKNESS),
                               ((TABLE_X[0] + TABLE_X[1]) / 2, 0.0, -TABLE_THICKNESS / 2),
                               TABLE_RGBA, mass=0.0, friction=TABLE_FRICTION)
        rgba = layout.colours
        self.cubes = [self._box((CUBE_SIZE,) * 3, (x, y, CUBE_SIZE / 2), rgba[colour],
                                mass=CUBE_MASS, friction=CUBE_FRICTION)
                      for colour, (x, y) in ((layout.left_colour, layout.left_xy),
                                             (layout.right_colour, layout.right_xy))]
        self.nico = Robot(c)
        self.opposite = (Robot(c, base_xyz=(2 * TABLE_CENTRE_X, 0.0, 0.0), base_yaw=math.pi)
                         if opposite_agent else None)
        for robot in (self.nico, self.opposite):
            if robot is not None:
                c.changeDynamics(robot.id, robot.hand_link, lateralFriction=self.hand_friction)
        self.start_positions = self.cube_positions()
        self.actor = actor
        self._camera = self._camera_matrices()
        self._colours = {(b, link): rgba for b in range(c.getNumBodies())
                         for (_, link, *_, rgba) in c.getVisualShapeData(c.getBodyUniqueId(b))}
        self._backdrop: tuple[np.ndarray, np.ndarray] | None = None

    def _box(self, size: tuple[float, float, float], xyz: tuple[float, float, float],
             rgba: tuple[float, ...], mass: float, friction: float) -> int:
        c = self.client
        half = [s / 2 for s in size]
        body = c.createMultiBody(baseMass=mass,
                                 baseCollisionShapeIndex=c.createCollisionShape(p.GEOM_BOX, halfExtents=half),
                                 baseVisualShapeIndex=c.createVisualShape(p.GEOM_BOX, halfExtents=half,
                                                                          rgbaColor=rgba),
                                 basePosition=xyz)
        c.changeDynamics(body, -1, lateralFriction=friction)
        return body

    def robot(self, agent: str) -> Robot:
        """``"nico"`` or ``"opposite"``."""
        if agent == "nico":
            return self.nico
        if agent == "opposite" and self.opposite is not None:
            return self.opposite
        raise ValueError(f"no agent {agent!r} in this scene; agents: nico"
                         + (", opposite" if self.opposite is not None else ""))

    # ---- state
    def step(self, substeps: int) -> None:
        """Advance the physics by ``substeps`` fixed time steps."""
        for _ in range(substeps):
            self.client.stepSimulation()

    def cube_positions(self) -> np.ndarray:
        """Centres of the left and right cube, (2, 3) world metres."""
        return np.array([self.client.getBasePositionAndOrientation(b)[0] for b in self.cubes])

    def cube_displacement(self) -> np.ndarray:
        """How far each cube moved since the world was built, (2, 3) metres."""
        return self.cube_positions() - self.start_positions

    # ---- the eye camera
    def _camera_matrices(self) -> tuple[list[float], list[float]]:
        eye, forward, up = self.nico.eye_pose()   # NICO's head does not move: compute once per world
        view = self.client.computeViewMatrix(eye.tolist(), (eye + forward).tolist(), up.tolist())
        height, width = self.image_size
        proj = self.client.computeProjectionMatrixFOV(CAMERA_FOV_DEG, width / height, 0.02, 2.0)
        return view, proj

    def _raw_render(self) -> tuple[np.ndarray, np.ndarray]:
        """TinyRenderer image of what is visible now: RGB (H, W, 3) uint8 and depth (H, W) float32."""
        view, proj = self._camera
        height, width = self.image_size
        _, _, rgba, depth, _ = self.client.getCameraImage(
            width, height, view, proj, renderer=p.ER_TINY_RENDERER, shadow=0,
            lightDirection=LIGHT_DIRECTION, flags=p.ER_NO_SEGMENTATION_MASK)
        rgb = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]
        depth = np.asarray(depth, dtype=np.float32).reshape(height, width)  # 1.0: nothing there
        return rgb, depth

    def moving_parts(self) -> list[tuple[int, int]]:
        """(body, link) of everything that moves: the two cubes and the actor's arm links."""
        robot = self.robot(self.actor)
        return [(b, -1) for b in self.cubes] + [(robot.id, j) for j in robot.arm_links]

    def _show(self, parts: list[tuple[int, int]] | None, visible: bool) -> None:
        """Show or hide (alpha 0: TinyRenderer skips it) the given parts; ``None``: all parts."""
        for (body, link), rgba in self._colours.items():
            if parts is None or (body, link) in parts:
                self.client.changeVisualShape(body, link, rgbaColor=rgba if visible else (*rgba[:3], 0.0))

    def refresh_backdrop(self) -> None:
        """Render the still parts once (colour + depth); call it after moving a still part by hand."""
        moving = self.moving_parts()
        self._show(None, True)
        self._show(moving, False)
        rgb, depth = self._raw_render()
        rgb = np.where(depth[..., None] >= 1.0, np.array(BACKGROUND_RGB, np.uint8), rgb)  # the wall
        self._backdrop = (rgb, depth)
        self._show(None, False)                   # from now on only the moving parts are drawn
        self._show(moving, True)

    def render(self) -> np.ndarray:
        """NICO's eye view, (height, width, 3) uint8 RGB (default 120 x 160): moving parts over the backdrop."""
        if self._backdrop is None:
            self.refresh_backdrop()
        back_rgb, back_depth = self._backdrop
        rgb, depth = self._raw_render()
        in_front = depth < back_depth                   # (H, W) bool: the z-buffer test
        frame = back_rgb.copy()
        frame[in_front] = rgb[in_front]
        return frame

    def render_full(self) -> np.ndarray:
        """The same view rendered in one pass with everything visible (slow; for checks)."""
        self._show(None, True)
        rgb, depth = self._raw_render()
        if self._backdrop is not None:               # restore the per-frame state
            self._show(None, False)
            self._show(self.moving_parts(), True)
        return np.where(depth[..., None] >= 1.0, np.array(BACKGROUND_RGB, np.uint8), rgb)

    def close(self) -> None:
        """Disconnect this world's physics server."""
        self.client.disconnect()
