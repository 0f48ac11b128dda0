"""The book's repository address is one configuration value: ``repository.url`` in ``_config.yml``.

Set, the pages get the repository and issues buttons and the Binder and Colab launch buttons, and
the notebooks a reader downloads (or opens in Colab) install pgae_lite from that address. Unset (the
default, while the project has no public address), none of them points anywhere: the buttons are
left out, and a downloaded notebook's install cell says that it names no repository instead of
installing from a dead address. The committed notebooks never hold the address: their install cell
reads ``REPOSITORY = ""``, filled in here, in the downloadable copies, at build time.
"""
from pathlib import Path

BUTTONS = ("use_repository_button", "use_issues_button", "use_edit_page_button", "use_source_button")


SHOWN = ("use_repository_button", "use_issues_button")          # turned on here when there is an address


def theme_options(options: dict) -> dict:
    """The theme options: the repository and issues buttons when the repository has an address (Jupyter
    Book refuses them without one, so _config.yml leaves them off), every link to it left out when not."""
    if (options.get("repository_url") or "").strip():
        return {**options, **{button: True for button in SHOWN}}
    return {**{k: v for k, v in options.items() if k not in ("launch_buttons", "repository_url")},
            **{button: False for button in BUTTONS}}


def fill_in(source: str, url: str) -> str:
    """A notebook's JSON text with the install cell's ``REPOSITORY = ""`` set to ``url``."""
    return source.replace('REPOSITORY = \\"\\"', f'REPOSITORY = \\"{url}\\"')


def configure(app, config):
    config.html_theme_options = theme_options(dict(config.html_theme_options or {}))


def fill_downloads(app, exception):
    url = (app.config.html_theme_options.get("repository_url") or "").strip()
    if exception is not None or not url:
        return
    for notebook in Path(app.outdir, "_sources").rglob("*.ipynb"):
        notebook.write_text(fill_in(notebook.read_text(encoding="utf-8"), url), encoding="utf-8")


def setup(app):
    app.connect("config-inited", configure, priority=900)
    app.connect("build-finished", fill_downloads)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
