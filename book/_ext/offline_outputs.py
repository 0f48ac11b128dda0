"""Keep notebook outputs from fetching anything from the network.

matplotlib's ``Animation.to_jshtml()`` starts with a ``<link>`` to Font Awesome
4.4 on a CDN, for the icons of its play/step buttons. The book's theme
(pydata-sphinx-theme) already ships Font Awesome 6 and its script draws every
``<i class="fa fa-...">`` on the page as an inline SVG icon, old icon names
included, so the link is only a failed request when the book is read offline.
This extension removes it from the HTML outputs of the executed notebooks.
"""
import re

from docutils import nodes

# The stylesheet link that matplotlib's animation template puts in every output.
CDN_STYLESHEET = re.compile(
    r'<link\s+rel="stylesheet"\s+href="https://maxcdn\.bootstrapcdn\.com/font-awesome/[^"]*"\s*/?>'
)


def strip_cdn_links(app, doctree, docname):
    for node in doctree.findall(nodes.raw):
        if "html" in node.get("format", "").split() and CDN_STYLESHEET.search(node.astext()):
            text = CDN_STYLESHEET.sub("", node.astext())
            node.replace(node.children[0], nodes.Text(text))


def setup(app):
    app.connect("doctree-resolved", strip_cdn_links)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
