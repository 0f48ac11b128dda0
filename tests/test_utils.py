"""pgae_lite.util.storage: atomic writes, config digests, the cache folder."""
from __future__ import annotations

import hashlib
import json

import pytest

from pgae_lite.util.storage import CACHE_ENV, atomic_path, atomic_write, atomic_write_text, cache_dir, config_digest


def test_atomic_write_replaces_the_file_and_leaves_no_temporary(tmp_path):
    path = tmp_path / "a.json"
    path.write_text("old")
    atomic_write_text(path, "new")
    assert path.read_text() == "new"
    with atomic_write(path) as f:
        f.write(b"bytes")
    assert path.read_bytes() == b"bytes"
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"]


def test_a_failed_write_keeps_the_old_file(tmp_path):
    path = tmp_path / "a.txt"
    path.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_write(path, "w") as f:
            f.write("half a fi")
            raise RuntimeError("crash")
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_temporary_names_are_unique_and_beside_the_file(tmp_path):
    path = tmp_path / "model.pt"
    with atomic_path(path) as a, atomic_path(path) as b:
        assert a != b and a.parent == b.parent == tmp_path
        assert str(a.name).startswith("model.pt.") and a.suffix == ".tmp"
        a.write_text("a")
        b.write_text("b")
    assert path.read_text() == "a"            # the last rename wins; neither file is ever half written


def test_config_digest_is_the_cache_keys_formula():
    config = {"name": "book", "iterations": 1000, "conv": [8, 16, 32, 64], "z": None}
    old = hashlib.sha1(json.dumps(config, sort_keys=True).encode()).hexdigest()[:12]
    assert config_digest(config) == old
    assert config_digest(dict(reversed(config.items()))) == old   # key order does not matter
    assert config_digest({**config, "iterations": 999}) != old


def test_cache_dir(monkeypatch, tmp_path):
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    assert cache_dir() == tmp_path
    monkeypatch.delenv(CACHE_ENV)                     # unset: the home cache (set but empty: refused)
    assert cache_dir().parts[-2:] == (".cache", "pgae_lite")
