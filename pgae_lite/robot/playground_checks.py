"""Argument checks of the playground (:mod:`~pgae_lite.robot.playground`): objects, choices.

No paper section. The ranges come from :mod:`~pgae_lite.world.patterns`: arrangements
0-11 (``ARRANGEMENTS``) and the playground's 12 actions, 0-11 (action k is
``ACTION_SIDES[k % 6]`` at speed ``k // 6``: 0 slowly, 1 fast). A bad argument
raises one sentence that names it, the value given and what is allowed.
"""
from __future__ import annotations

from typing import Mapping

from pgae_lite.cae import ChannelSeparatedCAE
from pgae_lite.evaluate.table1 import check_model_inputs
from pgae_lite.sim.dataset import DatasetConfig
from pgae_lite.util.checks import instance_of, shown, whole_number
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError
from pgae_lite.world.patterns import ACTION_SIDES, ARRANGEMENTS, pattern_parts
from pgae_lite.world.words import normalise_signal

SPEEDS = 2   # 0 slowly, 1 fast
#: The last pattern number (143): speed, arrangement and action at their largest.
LAST_PATTERN = SPEEDS * len(ARRANGEMENTS) * len(ACTION_SIDES) - 1


def arrangement_number(arrangement) -> int:
    """``arrangement`` when it is a whole number 0-11 (an index of ``ARRANGEMENTS``)."""
    return whole_number("arrangement", arrangement, 0, len(ARRANGEMENTS) - 1)


def action_number(action) -> int:
    """``action`` when it is a whole number 0-11 (6 actions x 2 speeds)."""
    return whole_number("action", action, 0, SPEEDS * len(ACTION_SIDES) - 1)


def check_objects(model, cae, normaliser, data, config) -> None:
    """Each object is what its name says (None allowed for ``cae`` and ``config``)."""
    check_model_inputs(model, data, normaliser)
    instance_of("cae", cae, ChannelSeparatedCAE, "a ChannelSeparatedCAE",
                optional=True)
    instance_of("config", config, DatasetConfig, "a DatasetConfig", optional=True)


def check_playground(models, cae, data, config, every, signal, arrangement, action,
                     signals: tuple[str, ...]) -> None:
    """The arguments of :class:`~pgae_lite.robot.playground.Playground`."""
    instance_of("models", models, Mapping, "a dict: name -> (model, normaliser)")
    if not models:
        raise ArgumentError("models is empty; give at least one, e.g. "
                            "{'PGAE': (model, normaliser)}")
    for name, pair in models.items():
        if not (isinstance(pair, tuple) and len(pair) == 2):
            raise ArgumentTypeError(f"models[{name!r}] must be a (model, normaliser) "
                                    f"pair; got {shown(pair)}")
        check_objects(pair[0], cae, pair[1], data, config)
    whole_number("every", every, 1)
    if normalise_signal(signal) not in signals:
        raise ArgumentError(f"signal {signal!r} is not offered here; the signals are: "
                            f"{', '.join(signals)}")
    if not len(data):
        raise ArgumentError("data holds no episodes: the playground needs a dataset with recordings to play, "
                            "e.g. simulated_dataset(get_profile('book'))")
    recorded = sorted({pattern_parts(int(p))[1] for p in data.pattern})
    if arrangement is not None and arrangement_number(arrangement) not in recorded:
        raise ArgumentError(f"arrangement {arrangement} is not in this dataset; its "
                            f"arrangements are: {', '.join(map(str, recorded))}")
    action_number(action)


__all__ = ["LAST_PATTERN", "SPEEDS", "action_number", "arrangement_number",
           "check_objects", "check_playground"]
