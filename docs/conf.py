"""Sphinx configuration of bistair's documentation site (``make docs``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
os.environ.setdefault("BISTAIR_PROGRESS_DELAY", "3600")  # no progress lines in the build

import bistair  # noqa: E402

project = "bistair"
author = "the bistair developers"
copyright = "2026, the bistair developers"  # noqa: A001
release = bistair.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_click",
    "sphinx_gallery.gen_gallery",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json", "auto_examples/*.md5"]
myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3

# each function and class on the page of the module that defines it (a package's re-exports
# in __all__ are not repeated: `bistair.sim.render` is a module, not also the function)
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False,
                           "ignore-module-all": True}
autodoc_typehints = "none"  # numpydoc's Parameters sections say the types
autosummary_generate = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"__init__\.py",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "matplotlib_animations": False,
    "plot_gallery": "True",
}

html_static_path = ["_static"]
nitpicky = False
suppress_warnings = ["myst.header"]

# -- the API reference: one page per layer, a section per module (as ARCHITECTURE.md) ------
LAYERS = [
    ("core", "Core: the building blocks on arrays",
     "One concept a module; the compiled passes of ``X.py`` in ``X_jit.py`` beside it."),
    ("codecs", "Codecs: one module (or package) per method",
     "The registry, the interface every method implements and the methods."),
    ("io", "I/O: captures in, results out", "Reading captures and specs, writing results "
     "atomically, previews."),
    ("geometry", "Geometry: calibration and 3-D", "Calibrations, boards, triangulation, "
     "height, two cameras."),
    ("sim", "The virtual rig", "Pinhole devices, scenes, ray tracing and exposure."),
    ("evaluation", "Evaluation", "Scores against the truth, the method comparison, reports."),
    ("acquire", "Acquisition", "Displays, cameras and the scan loop of ``bistair scan``."),
    ("app", "Jobs and the command line", "The jobs the commands run; the only layer that "
     "prints."),
]


def _modules(package: str) -> list[str]:
    base = ROOT / "src" / "bistair" / package
    names = []
    for path in sorted(base.rglob("*.py")):
        parts = path.relative_to(base).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") and p != "__init__" for p in parts) or parts[-1:] == ("cli",):
            continue
        names.append(".".join(("bistair", package, *parts)))
    return names


def _write_api() -> None:
    out = Path(__file__).parent / "api"
    out.mkdir(exist_ok=True)
    pages = []
    for package, title, text in LAYERS:
        lines = [title, "=" * len(title), "", text, ""]
        for module in _modules(package):
            lines += [f"``{module}``", "-" * (len(module) + 4), "",
                      f".. automodule:: {module}", "   :members:", "   :no-index:"
                      if False else "", ""]
        page = out / f"{package}.rst"
        content = "\n".join(lines).rstrip() + "\n"
        if not page.exists() or page.read_text() != content:
            page.write_text(content)
        pages.append(package)
    index = ["API reference", "=============", "",
             "The public functions and classes of every layer, from their docstrings, grouped "
             "as ``ARCHITECTURE.md`` groups them (imports point down this list).", "",
             ".. toctree::", "   :maxdepth: 1", "", *(f"   {p}" for p in pages), ""]
    content = "\n".join(index)
    page = out / "index.rst"
    if not page.exists() or page.read_text() != content:
        page.write_text(content)


_write_api()


# -- every spec field of every method, from the spec classes (docs/guide/spec-fields.md) ----
sys.path.insert(0, str(Path(__file__).parent))
import site_settings  # noqa: E402
from spec_fields import write_spec_fields_page  # noqa: E402

# -- the theme, no typographic replacements, the sidebars, the CLI reference's commands ----
smartquotes = site_settings.smartquotes
html_theme = site_settings.html_theme
html_title = site_settings.html_title
html_theme_options = site_settings.html_theme_options
html_show_sourcelink = site_settings.html_show_sourcelink

write_spec_fields_page()


def _skip_foreign(app, what, name, obj, skip, options):  # noqa: ANN001, ANN202
    """Leave out what another package defines (SciPy's ``cKDTree`` imported into a module,
    the ``set`` matplotlib writes into every Figure subclass)."""
    module = getattr(obj, "__module__", None)
    if isinstance(module, str) and not module.startswith("bistair"):
        return True
    return None


def setup(app):  # noqa: ANN001, ANN201
    app.connect("autodoc-skip-member", _skip_foreign)
    site_settings.setup_site(app)

