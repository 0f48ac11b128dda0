"""What every figure of the book shares: the joints' display names and tensors as numpy arrays.

No paper section: plumbing of :mod:`pgae_lite.viz`, used by all its modules.
"""
from __future__ import annotations

import numpy as np
import torch

JOINT_NAMES: tuple[str, ...] = tuple(f"joint {k}" for k in range(1, 6))


def _numpy(x) -> np.ndarray:
    return x.detach().cpu().numpy() if isinstance(x, torch.Tensor) else np.asarray(x)
