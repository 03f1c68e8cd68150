"""How the site's pages look and what the command-line reference shows: the settings
``conf.py`` takes, which ``tests/test_docs_site.py`` also builds a small site with.

- No typographic replacements (``smartquotes = False``): docutils turned ``--count`` in the
  commands' help into an en dash, ``–count``, and a command copied from the reference
  failed (``Got unexpected extra arguments (–count 3)``); quotes stay straight too.
- No primary sidebar on a top-level page without pages of its own (getting started, the
  command line): the theme showed the heading "Section Navigation" over nothing there. With
  ``sidebar_includehidden`` (its default, needed for the gallery's hidden toctree) it takes
  every section to have pages to list.
- Every method's ``bistair patterns METHOD`` in the reference: the command line makes those
  commands only when asked for (``bistair --help`` imports no codec), and sphinx-click lists
  only the commands a group holds.
"""

from __future__ import annotations

from typing import Any

smartquotes = False

html_theme = "pydata_sphinx_theme"
html_title = "bistair"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navbar_align": "left",
    "footer_start": ["copyright"],
    "footer_end": [],
}
html_show_sourcelink = False


def leaf_sections(app: Any, pagename: str, templatename: str, context: dict,
                  doctree: Any) -> None:
    """``html-page-context``: no primary sidebar on a top-level page without a toctree."""
    env, root = app.env, app.config.root_doc
    if pagename in env.toctree_includes.get(root, ()) and not env.toctree_includes.get(pagename):
        context["sidebars"] = []


def hold_method_commands() -> None:
    """Put every method's ``bistair patterns`` command into the group, for sphinx-click."""
    from bistair.app.cli.patterns import patterns

    for name in patterns.list_commands(None):  # type: ignore[arg-type]
        if name not in patterns.commands:
            patterns.add_command(patterns.get_command(None, name))  # type: ignore[arg-type]


def setup_site(app: Any) -> None:
    """What ``conf.py``'s ``setup`` connects."""
    hold_method_commands()
    app.connect("html-page-context", leaf_sections)
