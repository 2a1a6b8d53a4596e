"""The project's promises: the quick start and CI in step, the import layers, tests a reader finds.

Covers the README's quick start (``randvib study`` of :mod:`randvib.cli.study`)
and ``.ci/run``, the import-layer contract of pyproject.toml (from
:mod:`randvib.cli` down to :mod:`randvib.models`), and where each module's
tests are: every test module's docstring names the randvib modules it covers,
and every module is named by one or has a test file of its own name.
"""

import ast
import re
import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def quick_start_commands():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"<!-- quick-start.*?```bash\n(.*?)```", text, re.S).group(1)
    return [line for line in block.splitlines() if line.strip()]


def test_quick_start_has_exactly_two_commands():
    cmds = quick_start_commands()
    assert len(cmds) == 2
    assert cmds[0].startswith("pip install") and "randvib " in cmds[0]
    assert "pytest" in cmds[1]


def test_ci_runs_the_readme_test_command():
    # .ci/run extracts the second quick-start command; check that extraction
    script = (ROOT / ".ci" / "run").read_text()
    awk = re.search(r"cmd=\$\((awk .*?README\.md) \| sed -n 2p\)", script).group(1)
    extracted = subprocess.run(["bash", "-c", awk], cwd=ROOT, capture_output=True, text=True).stdout
    assert extracted.splitlines()[1] == quick_start_commands()[1]


def test_import_layers_hold():
    """The layer contract in pyproject.toml ([tool.importlinter]) is kept."""
    exe = shutil.which("lint-imports")
    assert exe is not None, "import-linter is a test dependency: pip install -e '.[test]'"
    proc = subprocess.run([exe], cwd=ROOT, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]


#: A module named in a docstring: ``randvib.x.y`` (perhaps a name inside it) or ``randvib/x/y.py``.
MODULE_NAME = re.compile(r"randvib(?:\.\w+)+|randvib(?:/\w+)+\.py")


def package_modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the package (a package by its ``__init__``)."""
    modules = {}
    for path in sorted((ROOT / "randvib").rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        modules[".".join(parts)] = path
    return modules


def named_modules(text: str, modules) -> set[str]:
    """The modules ``text`` names; ``randvib.simulate`` names the module that defines it."""
    import randvib

    found = set()
    for match in MODULE_NAME.findall(text):
        parts = match.removesuffix(".py").replace("/", ".").split(".")
        if parts[-1] == "__init__":
            parts.pop()
        while parts and ".".join(parts) not in modules:
            parts.pop()
        name = ".".join(parts)
        rest = match.removesuffix(".py").replace("/", ".")[len(name) + 1 :].split(".")[0]
        if name == "randvib" and rest in randvib._WHERE:  # a re-exported public name
            name = randvib._WHERE[rest]
        if name:
            found.add(name)
    return found


def docstrings_of_test_modules():
    return {
        path.name: ast.get_docstring(ast.parse(path.read_text())) or ""
        for path in sorted((ROOT / "tests").glob("test_*.py"))
    }


def test_every_test_module_names_the_modules_it_covers():
    modules = package_modules()
    unnamed = [
        name
        for name, doc in docstrings_of_test_modules().items()
        if not named_modules(doc, modules)
    ]
    assert unnamed == [], f"docstrings that name no randvib module: {unnamed}"


def test_every_module_has_tests_a_reader_can_find():
    """Named by a test module's docstring, or with a test file of its own name
    (randvib/montecarlo/rng.py: tests/test_rng.py)."""
    modules = package_modules()
    named = set().union(*(named_modules(d, modules) for d in docstrings_of_test_modules().values()))
    mirrors = {path.stem.removeprefix("test_") for path in (ROOT / "tests").glob("test_*.py")}
    missing = [
        name
        for name in modules
        if name not in named
        and name.rpartition(".")[2].lstrip("_") not in mirrors
        and not any(other.startswith(name + ".") for other in named)  # a package
    ]
    assert missing == [], f"modules no test module names: {missing}"
