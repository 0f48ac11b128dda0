"""The live playground's files: the trained models and the episodes, written into the built book.

At the end of an HTML build, ``pgae_lite.web.assets.export_web`` (what ``python -m pgae_lite
export-web`` runs) writes the playground's models (ONNX), their feature tables, the sentence
encoder for free text, the episodes and the simulator's closed-loop runs to ``_static/web/``
from the cache, for the profile the chapters ran with (``PGAE_LITE_PROFILE``, ``book`` when
unset). The chapters have trained those models by then (executed, or by the notebook run before
a build with execution off), so nothing is trained here unless the cache lacks a model. ``book/_js/pgae.js`` reads them.
"""
from pathlib import Path

from sphinx.util import logging

logger = logging.getLogger(__name__)


def export(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    from pgae_lite.config import get_profile
    from pgae_lite.web.assets import export_web

    manifest = export_web(Path(app.outdir) / "_static" / "web", get_profile())     # the profile, resolved here
    sizes = sum(m["bytes"] for m in manifest["models"].values())
    free = (manifest["free_text"] or {}).get("bytes", 0)
    test = sum(e["split"] == "test" for e in manifest["episodes"])
    logger.info(f"live playground: {len(manifest['models'])} models ({sizes / 1e6:.1f} MB of graphs, "
                f"{free / 1e6:.1f} MB more for free text), {test} test episodes and "
                f"{len(manifest['episodes']) - test} from training in _static/web ({manifest['profile']} profile)")


def setup(app):
    app.connect("build-finished", export)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
