"""Every message the page can show is typed once, as a template, and Python formats its errors from it.

The templates (pgae_lite/web/messages.py) are written into the page's data; the page fills ``{field}`` by
plain replacement, so a template holds named fields only, with no conversion or format spec.
"""
from __future__ import annotations

import string

import pytest

from pgae_lite.freeform import refusals
from pgae_lite.robot import closedloop, instructions, typed_text
from pgae_lite.util import checks
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError
from pgae_lite.web.messages import PAGE_MESSAGES, SOURCES, page_messages
from pgae_lite.world import words
from pgae_lite.world.words import LanguageError

MESSAGES = page_messages()


def fields(template: str) -> list[tuple[str, str | None, str | None]]:
    """(field name, conversion, format spec) of each field of ``template``."""
    return [(name, conversion, spec) for _, name, spec, conversion in string.Formatter().parse(template)
            if name is not None]


@pytest.mark.parametrize("key", sorted(MESSAGES))
def test_each_template_has_named_fields_only_and_no_conversion_or_spec(key):
    template = MESSAGES[key]
    assert key.isidentifier() and key == key.lower(), key                       # short snake_case
    for name, conversion, spec in fields(template):
        assert name.isidentifier(), (key, name)                                  # no "{}", "{0}", "{a.b}", "{a[0]}"
        assert conversion is None and not spec, (key, name, conversion, spec)
    filled = template.format(**{name: f"<{name}>" for name, _, _ in fields(template)})
    assert "{" not in filled and "}" not in filled, key                           # no stray or doubled brace


def test_the_keys_are_unique_across_the_modules_and_the_page():
    everyone = [key for module in SOURCES for key in module.MESSAGES] + list(PAGE_MESSAGES)
    assert len(everyone) == len(set(everyone)) == len(MESSAGES)
    assert {"unknown_words", "negation", "unknown_model", "whole_number_type"} <= set(MESSAGES)


def test_a_repeated_key_is_refused(monkeypatch):
    monkeypatch.setitem(PAGE_MESSAGES, "negation", "again")
    with pytest.raises(ValueError, match="negation"):
        page_messages()


def test_python_formats_its_errors_from_the_templates():
    vocabulary = ", ".join(sorted(w for w in words.VOCABULARY if w != words.BOS_EOS))
    with pytest.raises(LanguageError) as e:
        words.tokenize("push the red cube")
    assert str(e.value) == MESSAGES["unknown_words"].format(s="s", words="'the', 'cube'", text="'push the red cube'",
                                                            vocabulary=vocabulary)
    with pytest.raises(LanguageError) as e:
        words.parse_description("red push fast")
    assert str(e.value) == MESSAGES["wrong_slot"].format(word="'red'", slot="action", text="'red push fast'",
                                                         allowed="push, move-up, pull, move-down, slide, move-sideways")
    with pytest.raises(LanguageError) as e:
        words.normalise_signal("dance")
    assert str(e.value) == MESSAGES["unknown_signal"].format(signal="'dance'", signals=", ".join(words.SIGNALS))
    with pytest.raises(ArgumentError) as e:
        checks.whole_number("steps", 0, 1, 9)
    allowed = MESSAGES["whole_number_between"].format(low="1", high="9")
    assert str(e.value) == MESSAGES["whole_number_range"].format(name="steps", allowed=allowed, value="0")
    with pytest.raises(ArgumentTypeError) as e:
        checks.whole_number("steps", 2.0, 1)
    allowed = MESSAGES["whole_number_at_least"].format(low="1")
    assert str(e.value) == MESSAGES["whole_number_type"].format(name="steps", allowed=allowed, value="2.0",
                                                                type="float")
    with pytest.raises(ValueError) as e:
        instructions.check_route("sideways")
    assert str(e.value) == MESSAGES["unknown_route"].format(route="'sideways'", routes="'direct', 'said back'")
    with pytest.raises(ValueError) as e:
        closedloop.pattern_for("push green fast", 0)
    assert str(e.value) == MESSAGES["no_cube_in_arrangement"].format(colour="green", arrangement="0", left="red",
                                                                      right="blue")


def test_the_refusals_are_the_templates_filled():
    class Plain:
        word_lookup = None

    scene = MESSAGES["scene"].format(left="red", right="blue")
    assert refusals.refusal("don't push the red cube", Plain(), ("red", "blue")) == MESSAGES["negation"].format(
        text=repr("don't push the red cube"), negation=repr("don't push the red cube"), colour="red")
    assert refusals.refusal("push the green cube", Plain(), ("red", "blue")) == MESSAGES["absent_cube"].format(
        colour="green", as_read="", scene=scene)
    assert refusals.refusal("dance with the red cube", Plain()) == MESSAGES["cannot_verb"].format(
        verb="dance", actions=refusals.ACTIONS_SAID)
    chosen = MESSAGES["chosen_episode"].format(chosen="push red slowly")
    assert refusals.disagreement("", 0) == MESSAGES["no_readback"].format(words="'<EOS>'", chosen=chosen)


def test_the_typed_text_messages_name_the_model_that_cannot_read_it():
    class Lstm:
        reads_free_text = False

    with pytest.raises(LanguageError) as e:
        typed_text.read_typed(Lstm(), "execute", "push the red cube")
    assert str(e.value).startswith(MESSAGES["lstm_reads_vocabulary"].format(error="unknown words"))
