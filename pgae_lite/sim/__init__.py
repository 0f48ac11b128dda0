"""Our tabletop simulator (pybullet): NICO, a table, two cubes and an opposite agent, and the dataset recorded in it.

Paper, Sec. 4 (Dataset). The authors recorded their data in a Blender scene
that is not public; this subpackage builds an equivalent world from code a
student can read, one concept per module:

- ``robot``    the NICO-like robot (URDF generated in Python), joints, IK
- ``scene``    table, cubes, both robots, NICO's eye camera and renderer
- ``actions``  push / pull / slide as min-jerk hand paths through IK; the check
- ``record``   episodes: both views, seeds and retries, determinism; ``Simulation``, ``Execution``
- ``dataset``  the 864 simulated episodes: what to record, generation, cache, split (chapter 02)

Quick start::

    from pgae_lite.sim import record_episode
    ep = record_episode(pattern=0, variation=0)     # push red (left cube) slowly
    ep.joints.shape, ep.images.shape                # (100, 5), (100, 120, 160, 3)
"""
from pgae_lite.sim._quiet import silenced

with silenced(2):  # pybullet announces its build time on stderr when first imported
    import pybullet  # noqa: F401

from pgae_lite.sim.actions import ActionCheck, check_action
from pgae_lite.sim.record import (
    AGENTS,
    Episode,
    Execution,
    SimConfig,
    Simulation,
    episode_seed,
    execute_trajectory,
    record_episode,
    scene_layout,
)
from pgae_lite.sim.robot import HOME_POSE, JOINT_LIMITS, JOINT_NAMES, Robot
from pgae_lite.sim.scene import CUBE_RGBA, Scene, SceneLayout

__all__ = ["AGENTS", "ActionCheck", "CUBE_RGBA", "Episode", "Execution", "HOME_POSE", "JOINT_LIMITS",
           "JOINT_NAMES", "Robot", "Scene", "SceneLayout", "SimConfig", "Simulation", "check_action",
           "episode_seed", "execute_trajectory", "record_episode", "scene_layout"]
