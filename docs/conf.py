"""Sphinx configuration of randvib's documentation site.

Build it with ``python -m sphinx -W --keep-going -b html docs docs/_build/html``
(tests/test_docs.py runs the same build in CI, warnings as errors).
"""

import os
import re
import sys
from pathlib import Path

# the checkout; tests/test_docs.py builds a copy of docs/ elsewhere and names it
ROOT = Path(os.environ.get("RANDVIB_CHECKOUT", Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(ROOT))
# the gallery runs headless and on one numba thread (CI machines are small)
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import sphinx.ext.autosummary as _autosummary  # noqa: E402

import randvib  # noqa: E402

project = "randvib"
author = "randvib authors"
copyright = "randvib authors"
release = randvib.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "myst_parser",  # docs/conventions.md and docs/testing.md stay Markdown: one source
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",  # docs/cli.rst: the command line reference, generated from the parsers
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
templates_path = ["_templates"]

# -- Text -----------------------------------------------------------------------
# Smart quotes would also turn "--" into an en-dash, so the CLI reference
# (help texts such as "with --record") would show options that cannot be
# copied; keep quotes and ellipses only.
smartquotes_action = "qe"

# -- API reference ------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
# A module's page lists its public API: ``__all__`` where the module declares
# one (a driver module keeps its internals out of the reference that way).
autosummary_ignore_module_all = False
# The tables' one-line summaries are a docstring's first sentence; the paper's
# abbreviations ("Eq. 32", "Sec. 5", "Fig. 9") end no sentence.
_autosummary.WELL_KNOWN_ABBREVIATIONS = (
    *_autosummary.WELL_KNOWN_ABBREVIATIONS,
    "Eq.",
    "Eqs.",
    "Sec.",
    "Fig.",
    "Figs.",
    "Ref.",
)
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# numpydoc validation is limited to format errors that change what the page
# shows (a warning, hence an error, in the -W build): GL06 unknown section,
# GL07 sections out of order, PR10 a parameter line without " : " (prose inside
# a Parameters section becomes a parameter). Style checks (summary length,
# every return described, ...) are left to review.
numpydoc_validation_checks = {"GL06", "GL07", "PR10"}


def _numpydoc_with_one_template():
    """Make numpydoc compile its docstring template once per builder, not per docstring.

    numpydoc 1.x (``docscrape_sphinx.get_doc_object``) builds a Jinja environment
    and compiles ``numpydoc_docstring.rst`` afresh for every docstring it renders:
    about a fifth of this site's build time (py-spy, Sphinx 9, numpydoc 1.11). The
    template does not change during a build, so the compiled one is kept and handed
    to numpydoc's own parser; the rendered text is the same. Left as numpydoc has it
    where its internals differ from those this relies on.

    Called from :func:`setup`, not when this file is read: numpydoc's own
    ``setup`` puts back the ``get_doc_object`` it imported (its default
    argument), and Sphinx runs the extensions' ``setup`` after reading this
    file but before this file's ``setup``.
    """
    try:
        import numpydoc.numpydoc as extension
        from numpydoc import docscrape, docscrape_sphinx
    except ImportError:
        return
    original = getattr(extension, "get_doc_object", None)
    classes = ("SphinxClassDoc", "SphinxFunctionDoc", "SphinxObjDoc")
    if original is not docscrape_sphinx.get_doc_object or not all(
        hasattr(docscrape_sphinx, name) for name in classes
    ):
        return
    templates = {}

    def get_doc_object(obj, what=None, doc=None, config=None, builder=None):
        config = {} if config is None else config
        if id(builder) not in templates:
            first = {}
            original(len, config=first, builder=builder)
            templates[id(builder)] = first["template"]
        config["template"] = templates[id(builder)]
        return docscrape.get_doc_object(
            obj,
            what=what,
            doc=doc,
            config=config,
            class_doc=docscrape_sphinx.SphinxClassDoc,
            func_doc=docscrape_sphinx.SphinxFunctionDoc,
            obj_doc=docscrape_sphinx.SphinxObjDoc,
        )

    extension.get_doc_object = get_doc_object


def _numpydoc_selected_checks_only():
    """Make numpydoc run only the checks it reports (``numpydoc_validation_checks``).

    numpydoc 1.x runs all its ~50 checks on every docstring and then reports the
    selected ones (its own TODO in ``mangle_docstrings`` says so). Several of the
    others read and tokenize the object's source (its definition line, whether a
    method returns something, ``# numpydoc ignore`` comments): about a tenth of
    this site's build (cProfile, numpydoc 1.11). The three checks kept here read the
    parsed docstring only, and are numpydoc's own code for them (``validate.validate``);
    randvib has no ``# numpydoc ignore`` comments. Left as numpydoc has it where the
    selection or numpydoc's internals differ from those this relies on.
    """
    try:
        import numpydoc.numpydoc as extension
        from numpydoc import validate as numpydoc_validate
    except ImportError:
        return
    if numpydoc_validation_checks != {"GL06", "GL07", "PR10"} or not all(
        hasattr(numpydoc_validate, name) for name in ("ALLOWED_SECTIONS", "Validator", "error")
    ):
        return
    allowed, error = numpydoc_validate.ALLOWED_SECTIONS, numpydoc_validate.error

    def validate(obj):
        doc = numpydoc_validate.Validator(obj)
        errs = []
        if doc.raw_doc:
            titles = doc.section_titles
            for section in titles:
                if section not in allowed:
                    errs.append(error("GL06", section=section, allowed_sections=", ".join(allowed)))
            correct_order = [section for section in allowed if section in titles]
            if correct_order != titles:
                errs.append(error("GL07", correct_sections=", ".join(correct_order)))
            for param in doc.doc_all_parameters:
                if not param.startswith("*") and not doc.parameter_type(param) and ":" in param:
                    errs.append(error("PR10", param_name=param.split(":")[0]))
        return {"docstring": doc.clean_doc, "errors": errs}

    extension.validate = validate


intersphinx_mapping = {}

# -- Markdown -----------------------------------------------------------------
myst_heading_anchors = 3

# -- Gallery ------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",  # every example runs: their output is the point
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "reset_modules": ("matplotlib",),
    "plot_gallery": "True",
    # a script's last expression is shown as its output; the artists that
    # plotting calls return (a legend, lines, a figure) are not output
    "ignore_repr_types": r"matplotlib[.](text|axes|legend|lines|figure|collections|image|container)",
}

# -- HTML ---------------------------------------------------------------------
html_theme = "furo"
html_title = f"randvib {release}"
html_static_path = []


# -- Plain-text notation in docstrings ----------------------------------------
# The docstrings are written for ``help()`` as much as for this site and use
# absolute values such as |z| or E|v|; in reST a pair of bars is a substitution
# reference. Escape bars outside inline literals and roles, leaving tables (a
# bar at the start of a line) as they are.
_LITERAL = re.compile(r"(``.*?``|`[^`]*`)")
_TABLE_ROW = re.compile(r"^\s*(\+[-=+]+\+?\s*$|\|\s)")


def _escape_bars(line: str) -> str:
    if _TABLE_ROW.match(line):
        return line
    parts = _LITERAL.split(line)
    return "".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(parts))


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def _escape_docstring(app, what, name, obj, options, lines):
    """Escape the bars of prose lines; doctests and literal blocks stay verbatim."""
    verbatim_above = None  # indentation of the line that opened a literal block
    in_doctest = False
    for i, line in enumerate(lines):
        if not line.strip():
            in_doctest = False
            continue
        if verbatim_above is not None and _indent(line) > verbatim_above:
            continue
        verbatim_above = None
        in_doctest = in_doctest or line.lstrip().startswith(">>>")
        if in_doctest:
            continue
        lines[i] = _escape_bars(line)
        if line.rstrip().endswith("::"):
            verbatim_above = _indent(line)


def setup(app):
    _numpydoc_with_one_template()
    _numpydoc_selected_checks_only()
    app.connect("autodoc-process-docstring", _escape_docstring)
