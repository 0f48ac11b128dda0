"""pgae_lite.world.colours and the package with a new colour: the default world is the paper's,
an extended one records, trains and is checked (the guided project)."""
from __future__ import annotations

from dataclasses import asdict

import numpy as np
import pytest
import torch

from pgae_lite.config import ModelConfig, get_profile
from pgae_lite.data.dataset import from_recordings
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import Predictions
from pgae_lite.exercises import check_new_colour
from pgae_lite.model.pgae import PGAE
from pgae_lite.sim.dataset import GENERATOR_VERSION, DatasetConfig
from pgae_lite.util.storage import config_digest
from pgae_lite.world import words as L
from pgae_lite.world.colours import DEFAULT_WORLD, World, with_colour
from pgae_lite.world.patterns import TEST_PATTERNS, Pattern
from pgae_lite.world.words import DEFAULT_LEXICON, LanguageError

ORANGE = (0.98, 0.50, 0.05, 1.0)
WORLD = with_colour("orange", "amber", ORANGE)


def tiny(world: World, patterns, seed: int = 0):
    """One random recording of each pattern (the right lengths, joints in [-1, 1])."""
    rng = np.random.default_rng(seed)

    def rec(n):
        p = world.pattern(n)
        return (p, f"toy/{n}", rng.uniform(-1, 1, (p.steps, 5)).astype(np.float32),
                rng.normal(size=(p.steps, 30)), rng.normal(size=(p.steps, 30)))
    return from_recordings((rec(n) for n in patterns), source="toy")


# ------------------------------------------------------------------ the default world
def test_default_world_is_the_papers():
    assert DEFAULT_WORLD.n_patterns == 144 and DEFAULT_WORLD.new_patterns == ()
    for n in range(144):
        ours, paper = DEFAULT_WORLD.pattern(n), Pattern.from_number(n)
        assert (ours.action, ours.side, ours.speed, ours.left, ours.right) == \
               (paper.action, paper.side, paper.speed, paper.left, paper.right)
        assert ours.is_test == paper.is_test
        assert (ours.descriptions() == paper.descriptions()).all()


def test_default_keys_and_weights_unchanged():
    for name in ("smoke", "book"):
        data = get_profile(name).data
        old = {k: v for k, v in asdict(data).items() if k != "world"}   # as before
        assert data.key() == config_digest({"version": GENERATOR_VERSION, **old})
        assert "world" not in data.to_dict()
    assert DEFAULT_LEXICON.word_weights() == L.WORD_WEIGHTS     # the authors', by rule
    assert torch.equal(L.word_weights(DEFAULT_LEXICON), L.word_weights())
    torch.manual_seed(0)
    a = PGAE(ModelConfig(units=8))
    torch.manual_seed(0)
    b = PGAE(ModelConfig(units=8), DEFAULT_LEXICON)
    pairs = zip(a.state_dict().values(), b.state_dict().values())
    assert all(torch.equal(x, y) for x, y in pairs)


# ------------------------------------------------------------------ the extended world
def test_with_colour_appends_words():
    lex = WORLD.lexicon
    assert lex.vocabulary[:23] == L.VOCABULARY
    assert lex.vocabulary[23:] == ("orange", "amber")
    assert lex.input_dim == 30 and lex.colours[-1] == "orange"
    weights = lex.word_weights()
    assert weights["orange"] == weights["amber"] == weights["red"]
    assert np.mean(list(weights.values())) == pytest.approx(1.0, abs=1e-3)
    assert L.parse_description("move up amber quickly", lex) == ("push", "orange",
                                                                  "fast")
    assert len(set(L.equivalent_descriptions("pull", "orange", "slowly", lex))) == 8
    assert L.decode([14, 24, 19, 0], lex) == "push amber slowly"
    with pytest.raises(LanguageError, match="orange"):
        L.parse_description("push orange fast")            # not a word of the paper's


@pytest.mark.parametrize("args, match", [
    (("red", "ruby", ORANGE), "already a word"),
    (("orange", "scarlet", ORANGE), "already a word"),
    (("Orange", "amber", ORANGE), "lowercase"),
    (("orange", "amber", (250, 128, 13, 1)), r"\[0, 1\]"),
    (("orange", "amber", ORANGE[:3]), "4 numbers"),
])
def test_with_colour_refuses_bad_input(args, match):
    with pytest.raises(ValueError, match=match):
        with_colour(*args)
    with pytest.raises(LanguageError, match="partners"):
        with_colour("orange", "amber", ORANGE, partners=("pink",))


def test_new_patterns_numbering_and_split():
    assert WORLD.n_patterns == 192 and WORLD.new_patterns == tuple(range(144, 192))
    assert WORLD.arrangements[12:] == (("orange", "blue"), ("blue", "orange"),
                                       ("orange", "violet"), ("violet", "orange"))
    for n in range(192):
        assert WORLD.pattern_number(*WORLD.pattern_parts(n)) == n
    p = WORLD.pattern(144 + 12 * 1 + 6 * 1 + 3)        # arrangement 13, fast, push R
    assert (p.left, p.right, p.code, p.colour) == ("blue", "orange", "PUSH-R-FAST",
                                                   "orange")
    with pytest.raises(ValueError, match="0-143"):
        WORLD.pattern(192)
    new_test = [n for n in WORLD.test_patterns if n >= 144]
    assert TEST_PATTERNS < WORLD.test_patterns and len(new_test) == 12       # a quarter
    meanings = {}
    for n in WORLD.new_patterns:
        q = WORLD.pattern(n)
        if q.colour == "orange":
            meanings.setdefault((q.action, q.speed), []).append(q.is_test)
    assert len(meanings) == 6                      # every orange meaning is held out
    assert all(sum(t) == 1 and len(t) - sum(t) == 3 for t in meanings.values())   # once
    codes = {Pattern.from_number(n).code for n in range(144)}   # the 12 action codes
    assert {WORLD.pattern(n).code for n in new_test} == codes        # each one tested
    orange_words = {23, 24}
    assert all(set(WORLD.pattern(n).descriptions()[:, 1]) <= orange_words
               for n in WORLD.new_patterns if WORLD.pattern(n).colour == "orange")


def test_dataset_config_keys_the_world():
    new = DatasetConfig(variations=1, patterns=(144,), world=WORLD)
    assert new.key() != DatasetConfig(variations=1, patterns=(144,)).key()
    assert new.to_dict()["world"]["vocabulary"][-2:] == ["orange", "amber"]
    assert DatasetConfig(world=WORLD).pattern_list() == list(range(192))


# ------------------------------------------------------------------ simulator
def test_simulator_builds_and_records_the_new_cube():
    from pgae_lite.sim import Scene, SceneLayout
    from pgae_lite.sim.record import record_episode, scene_layout

    with pytest.raises(ValueError, match="palette"):
        SceneLayout("orange", "blue")
    layout = scene_layout(144, world=WORLD)
    assert (layout.left_colour, layout.right_colour) == ("orange", "blue")
    scene = Scene(layout, opposite_agent=False)
    try:
        frame = scene.render().astype(int)
    finally:
        scene.close()
    orange = (np.abs(frame - [250, 128, 13]).sum(-1) < 90).sum()
    assert orange > 50, "the orange cube is in NICO's view"
    ep = record_episode(150, 0, world=WORLD)     # (orange, blue): push left cube fast
    assert ep.valid and ep.joints.shape == (50, 5) and ep.displacement[0, 0] > 0.04


# ------------------------------------------------------------------ model and training
def test_pgae_for_the_larger_vocabulary_trains_and_loads(tmp_path):
    from pgae_lite.config import with_world
    from pgae_lite.runs.pipeline import load_model
    from pgae_lite.train.checkpoint import CHECKPOINT
    from pgae_lite.train.loop import train
    from pgae_lite.util.storage import CheckpointMismatchError

    data = tiny(WORLD, [0, 77, 144, 150, 165, 184])
    assert data.descriptions.max() == 24
    profile = get_profile("smoke", epochs=1, checkpoint_every=1)
    model = PGAE(profile.model, WORLD.lexicon)
    assert model.language_encoder.input_dim == 30
    trained = train(data, profile, out_dir=tmp_path, progress=False, model=model)
    assert trained.model.language_decoder.out.out_features == 25
    loaded, normaliser, _ = load_model(tmp_path / CHECKPOINT, device="cpu", lexicon=WORLD.lexicon)
    assert all(torch.equal(a.cpu(), b) for a, b in
               zip(trained.model.state_dict().values(), loaded.state_dict().values()))
    with pytest.raises(CheckpointMismatchError, match="do not fit the model"):   # the paper's 23 words
        load_model(tmp_path / CHECKPOINT, device="cpu")
    # in the world's profile the one loop builds the model for the world's words itself
    built = train(data, with_world(profile, WORLD), out_dir=tmp_path / "built", progress=False)
    assert built.model.lexicon == WORLD.lexicon and built.model.language_decoder.out.out_features == 25
    again, _, _ = load_model(tmp_path / "built" / CHECKPOINT, device="cpu", lexicon=WORLD.lexicon)
    assert all(torch.equal(a.cpu(), b) for a, b in zip(built.model.state_dict().values(), again.state_dict().values()))


# ------------------------------------------------------------------ the check
def test_check_colour_knows_the_worlds_colours():
    from pgae_lite.exercises import check_colour

    assert not check_colour("orange", ORANGE, world=WORLD)           # already there
    assert check_colour("pink", (1.0, 0.4, 0.8, 1.0), world=WORLD)
    darker = (0.98, 0.45, 0.05, 1.0)                     # near the new orange
    assert check_colour("tangerine", darker)
    assert not check_colour("tangerine", darker, world=WORLD)


def test_check_new_colour_fails_for_an_untrained_model():
    data = tiny(WORLD, list(range(144, 192)))
    torch.manual_seed(0)
    model = PGAE(ModelConfig(units=8), WORLD.lexicon)
    normaliser = Normaliser.fit(data.split("train"))
    result = check_new_colour(model, normaliser, data, "orange")
    assert not result and "describe" in str(result) and "execute" in str(result)
    old = check_new_colour(PGAE(ModelConfig(units=8)), normaliser, data, "orange")
    assert not old and "no colour 'orange'" in str(old)
    without = tiny(WORLD, [0, 2, 144])                    # no held-out orange episode
    assert not check_new_colour(model, Normaliser.fit(without), without, "orange")


def test_check_new_colour_passes_a_perfect_model(monkeypatch):
    from pgae_lite.exercises import world as checks

    data = tiny(WORLD, list(range(144, 192)))

    def perfect(model, subset, normaliser, signal):
        joints = np.where(subset.mask[..., None], subset.joints, np.nan)
        return Predictions(signal, subset.ids, [""] * len(subset), joints, joints,
                           np.ones(len(subset), bool), np.zeros((len(subset), 2)))
    monkeypatch.setattr(checks, "predict", perfect)
    model = PGAE(ModelConfig(units=8), WORLD.lexicon)
    result = check_new_colour(model, None, data, "orange")
    assert result, str(result)
    assert "100.0% right on the 6 held-out episodes" in str(result)
