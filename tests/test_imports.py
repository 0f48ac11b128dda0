"""The package's import graph: its layers, no circles, and one module owns the profiles.

Every module of ``pgae_lite`` is parsed (not imported) and every import of another
module of the package is an edge, whether it sits at the top of the file, inside a
function or under ``if TYPE_CHECKING``: a function-level import that closes a
circle only moves the failure to the first call.
"""
from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "pgae_lite"


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def imported_modules(name: str) -> set[str]:
    """The package's modules that module ``name`` imports, anywhere in its code."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            # "from . import x": x may be a module of the package
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names]
        else:
            continue
        for target in targets:
            while target and target not in MODULES:          # "pgae_lite.sim.record.Episode" -> the module
                target = target.rpartition(".")[0]
            if not target or target == name:
                continue
            found.add(target)
            # Importing a.b.c runs the __init__ of every package on the way, unless we are inside it.
            parts = target.split(".")
            for i in range(1, len(parts)):
                parent = ".".join(parts[:i])
                if parent in MODULES and not (name + ".").startswith(parent + "."):
                    found.add(parent)
    return found


GRAPH = {name: imported_modules(name) for name in MODULES}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A list of modules that import each other in a circle (first == last), or None."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        state[node] = "done"
        stack.pop()
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def reachable(name: str) -> set[str]:
    seen, todo = set(), [name]
    while todo:
        for nxt in GRAPH[todo.pop()] - seen:
            seen.add(nxt)
            todo.append(nxt)
    return seen


def unit(name: str) -> str:
    """The top-level entry of the package that module ``name`` belongs to: a folder or a module."""
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else "pgae_lite"


#: Each folder (or top-level module) and the folders it may import: the package's layers, lowest first.
#: The model imports only the world, the dataset type and the utilities (never the simulator, which records
#: our dataset above it); the pretrained encoders (bert) build on the model, free-form language on them;
#: the one training loop on the model alone (its caller hands it the rest); config composes each part's
#: settings; runs, robot and web are on top, and course (handing the book out) above everything, imported by
#: the command line alone.
LAYERS = {
    "util": set(),
    "world": {"util"},
    "data": {"world", "util"},
    "sim": {"data", "world", "util"},
    "cae": {"util"},
    "model": {"data", "world", "util"},
    "bert": {"model", "world", "util"},
    "freeform": {"bert", "model", "world", "util"},
    "evaluate": {"model", "data", "world", "util"},
    "viz": {"model", "data", "world", "util"},
    "train": {"model", "data", "world", "util"},
    "config": {"train", "model", "cae", "sim", "world", "util"},
    "exercises": {"train", "evaluate", "model", "cae", "data", "sim", "world", "util"},
    "runs": {"config", "freeform", "bert", "train", "evaluate", "model", "cae", "data", "sim", "world", "util"},
    "robot": {"runs", "config", "freeform", "evaluate", "bert", "model", "cae", "data", "sim", "viz", "world",
              "util"},
    "web": {"robot", "runs", "config", "freeform", "train", "evaluate", "bert", "model", "cae", "data", "sim",
            "world", "util"},
    "course": {"web", "robot", "runs", "config", "freeform", "train", "evaluate", "bert", "model", "cae", "data",
               "sim", "viz", "exercises", "world", "util"},
    "__main__": {"course", "web", "runs", "config", "sim", "data", "util"},
    "pgae_lite": set(),
}


def test_the_graph_is_read():
    assert GRAPH["pgae_lite.train.loop"] >= {"pgae_lite.model.build", "pgae_lite.util.storage"}
    assert "pgae_lite.train.loop" in GRAPH["pgae_lite.runs.pipeline"]           # a function-level import counts
    assert "pgae_lite.world.words" in GRAPH["pgae_lite.sim.actions"]
    assert "pgae_lite.sim" in GRAPH["pgae_lite.robot.closedloop"]             # a subpackage runs its __init__
    assert "pgae_lite.world.patterns" in GRAPH["pgae_lite.robot.playground"]   # from pgae_lite.world import patterns
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]


def test_no_import_cycles():
    cycle = find_cycle(GRAPH)
    assert cycle is None, "modules import each other in a circle: " + " -> ".join(cycle)


def test_every_entry_of_the_package_has_a_layer():
    assert {unit(name) for name in MODULES} == set(LAYERS)
    assert find_cycle({u: set(allowed) for u, allowed in LAYERS.items()}) is None


def test_each_folder_imports_only_the_folders_below_it():
    wrong = sorted(f"{name} imports {target}" for name, targets in GRAPH.items() for target in targets
                   if unit(target) != unit(name) and unit(target) not in LAYERS[unit(name)])
    assert not wrong, "imports against the layers of LAYERS:\n" + "\n".join(wrong)


def test_the_model_imports_no_simulator_cae_or_transformer():
    """A student on the authors' data or the toy data imports PGAE without pybullet or transformers."""
    code = ("import sys; import pgae_lite.model.pgae, pgae_lite.model.config, pgae_lite.data.dataset, "
            "pgae_lite.data.toy, pgae_lite.evaluate.table1; print(' '.join(sorted(sys.modules)))")
    loaded = set(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                                cwd=PACKAGE.parent).stdout.split())
    assert "pgae_lite.model.pgae" in loaded                       # the check can see what was imported
    unwanted = {m for m in loaded if m.split(".")[0] in ("pybullet", "transformers", "pybullet_data")
                or m.startswith(("pgae_lite.sim", "pgae_lite.bert", "pgae_lite.runs", "pgae_lite.robot"))
                or m in ("pgae_lite.cae", "pgae_lite.config", "pgae_lite.sim.dataset")}
    assert not unwanted, sorted(unwanted)


def test_the_training_loop_reaches_no_pretrained_encoder_and_no_free_form_language():
    """One loop trains every model; a pretrained encoder is built by its settings, phrasings are handed in."""
    reached = {unit(m) for m in reachable("pgae_lite.train.loop")}
    assert reached <= {"model", "data", "world", "util", "train"}, sorted(reached)


def test_plumbing_imports_nothing_above_it():
    assert reachable("pgae_lite.util.storage") == {"pgae_lite.util.errors", "pgae_lite.util.atomic_files",
                                                   "pgae_lite.util.folder_lock"}
    assert not reachable("pgae_lite.util.errors")
    assert reachable("pgae_lite.world.patterns") == {"pgae_lite.world.words", "pgae_lite.world.typed",
                                                     "pgae_lite.util.errors", "pgae_lite.util"}
    assert "pgae_lite.runs.reproduce" not in reachable("pgae_lite.runs.pipeline")
    assert "pgae_lite.robot.instructions" not in reachable("pgae_lite.robot.closedloop")


def test_every_module_is_at_most_350_lines():
    lines = {name: len(path.read_text(encoding="utf-8").splitlines()) for name, path in MODULES.items()}
    long = {name: n for name, n in lines.items() if n > 350}
    assert not long, f"split these modules (at most 350 lines each): {long}"


def test_only_config_reads_the_profile_variable():
    """Every module asks config.profile_name(); only config.py looks the variable up in os.environ."""
    files = sorted(PACKAGE.rglob("*.py"))
    reads = re.compile(r"(environ\.get\(|environ\[|getenv\()\s*(PROFILE_ENV|[\"']PGAE_LITE_PROFILE)")
    readers = [p.relative_to(PACKAGE).as_posix() for p in files if reads.search(p.read_text(encoding="utf-8"))]
    assert readers == ["config.py"], f"only config.py may read PGAE_LITE_PROFILE from the environment; found {readers}"
