"""Plots and tables for the book's chapters (matplotlib and pandas), one module per topic.

Every function returns its figure (or DataFrame) and shows nothing itself:
a notebook displays what a cell returns, a script may save it. Nothing here
changes the model or the data.

- ``scenes``      the world: frames, animations, the 144 patterns, joints by action
                  (chapters 01, 02; paper, Sec. 4)
- ``vision``      seeing: colour channels, reconstructions, the CAE's training curves, visual features
                  (chapter 03; Sec. 3)
- ``model``       the model from inside: gates, joints, training curves, signals, confused words
                  (chapters 04-06; Sec. 3 and Table 1)
- ``embeddings``  language spaces: word similarities, maps of sentence vectors (chapter 05; Sec. 3 and 5)

Every public function is importable from here, e.g. ``from pgae_lite.viz import plot_gates``.
"""
from pgae_lite.viz.embeddings import WORD_COLOURS, plot_point_map, plot_similarity
from pgae_lite.viz.model import (
                    SIGNAL_COLOURS,
                    plot_gates,
                    plot_histories,
                    plot_history,
                    plot_joints,
                    plot_mean_gates,
                    plot_word_confusion,
                    prediction_frame,
                    signal_table,
                    word_confusion,
                    wrong_words,
)
from pgae_lite.viz.scenes import animate_frames, plot_frames, plot_joints_by_action, plot_patterns
from pgae_lite.viz.vision import (
                    CHANNEL_COLOURS,
                    plot_cae_history,
                    plot_channels,
                    plot_feature_rows,
                    plot_features_over_time,
                    plot_reconstructions,
                    plot_vision,
)

__all__ = ["plot_frames", "animate_frames", "plot_patterns", "plot_joints_by_action",
           "CHANNEL_COLOURS", "plot_channels", "plot_reconstructions", "plot_cae_history", "plot_features_over_time",
           "plot_feature_rows", "plot_vision",
           "SIGNAL_COLOURS", "plot_gates", "plot_joints", "plot_history", "signal_table", "prediction_frame",
           "wrong_words", "plot_histories", "plot_mean_gates", "word_confusion", "plot_word_confusion",
           "WORD_COLOURS", "plot_similarity", "plot_point_map"]
