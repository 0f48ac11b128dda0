"""Every message the live playground can show, as templates written into the page's data (not in the paper).

The modules that raise these errors in Python each hold theirs in a dict ``MESSAGES`` and format them
from it; the page reads the same templates from its data and fills them, so a message is typed once.
A template is ``str.format`` text with named fields only (no conversions, no format specs): the caller
hands each field already written (a repr where the message quotes), so the page fills ``{field}`` by
plain replacement. The page's own few messages, which no Python code raises, are :data:`PAGE_MESSAGES`.
"""
from __future__ import annotations

from pgae_lite.freeform import refusals
from pgae_lite.robot import closedloop, instructions, playground, typed_text
from pgae_lite.util import checks
from pgae_lite.world import words

#: The messages only the page says: its models, its episodes and the files it loads.
PAGE_MESSAGES: dict[str, str] = {
    "unknown_model": "unknown model {model}; the models are: {models}",
    "no_episode": "no episode {episode} in this page; e.g. {example}",
    "no_sentence_encoder": "this book was built without the sentence encoder: the page reads descriptions only",
    "cannot_load": "cannot load {url} (HTTP {status}): the book was built without its live models",
    "this_page": "this page (it holds every test recording and the first recording of each training pattern)",
}

#: The modules whose ``MESSAGES`` the page holds, in the order they are merged.
SOURCES = (words, checks, typed_text, instructions, closedloop, playground, refusals)


def page_messages() -> dict[str, str]:
    """Key -> template: every module's ``MESSAGES`` of :data:`SOURCES`, then :data:`PAGE_MESSAGES`; a
    ValueError if two of them use one key."""
    merged: dict[str, str] = {}
    for where, messages in [(m.__name__, m.MESSAGES) for m in SOURCES] + [(__name__, PAGE_MESSAGES)]:
        repeated = sorted(set(merged) & set(messages))
        if repeated:
            raise ValueError(f"the message keys {repeated} of {where} are used by another module already")
        merged |= messages
    return merged


__all__ = ["PAGE_MESSAGES", "SOURCES", "page_messages"]
