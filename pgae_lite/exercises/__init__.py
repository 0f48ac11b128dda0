"""Check functions for the book's exercises: your version against the package's.

Each check runs a student's code next to the reference on seeded random inputs and returns a
:class:`~pgae_lite.exercises.result.CheckResult`: a short report (what matched; where and by how
much it did not, with a hint tied to the paper's equation), truthy only when everything matched
(``assert check_gmu(MyGMU)``).
A wrong answer never raises. Paper, Sec. 3: the LSTM step, the GMU or a replacement, the signals, the
channel-separated CAE; Sec. 4: the vocabulary, our simulator's cube colours, Table 1's nRMSE and our closed
loop; Sec. 2: the binding loss of PGAE's predecessors. The course's problem sets
(``course/problem_sets/``) grade with these checks.

- ``result``  :class:`~pgae_lite.exercises.result.CheckResult` and how a check runs and compares student code
- ``world``   chapters 01-03: ``check_vocabulary``, ``check_colour``; the guided project
              "Teach NICO a new colour": ``check_new_colour``
- ``seeing``  chapter 03: ``check_channel_split``, ``check_cae_loss``, ``check_visual_features``
- ``model``   chapters 04-05: ``check_peephole_step``, ``check_lstm_step``, ``check_gmu``,
              ``check_bottleneck``, ``check_signal_probs``
- ``acting``  chapter 07: ``check_nrmse``, ``check_tracking_target``, ``check_delayed``
- ``family``  chapter 09: ``check_binding_loss``

Every check is importable from here, e.g. ``from pgae_lite.exercises import check_gmu``.
"""
from pgae_lite.exercises.acting import check_delayed, check_nrmse, check_tracking_target
from pgae_lite.exercises.family import check_binding_loss
from pgae_lite.exercises.model import (
                                      check_bottleneck,
                                      check_gmu,
                                      check_lstm_step,
                                      check_peephole_step,
                                      check_signal_probs,
)
from pgae_lite.exercises.result import CheckResult
from pgae_lite.exercises.seeing import check_cae_loss, check_channel_split, check_visual_features
from pgae_lite.exercises.world import check_colour, check_new_colour, check_vocabulary

__all__ = ["CheckResult", "check_vocabulary", "check_colour", "check_new_colour",
           "check_peephole_step", "check_lstm_step", "check_gmu",
           "check_bottleneck", "check_signal_probs", "check_binding_loss",
           "check_channel_split", "check_cae_loss", "check_visual_features",
           "check_nrmse", "check_tracking_target", "check_delayed"]
