"""The server's studies folder: the only place a browser's study names lead to.

A reviewer picks finished map stores, design-load envelope stores and uncertainty results **by
name from a list** the server made of this folder (a store is an envelope when its attributes
say so, a map otherwise); new studies get names the server chooses.  A name is accepted only if
it is in the list made afresh at the moment of use; a name with a path separator, a NUL byte,
more than :data:`MAX_NAME` characters, a leading dot, or an entry that is a symbolic link,
resolves outside the folder or (a store) holds a symbolic link anywhere inside, is not in the
list.  Every refusal raises :class:`StudyNameRefused` with one message, the same whether or not
something of that name exists anywhere (no file oracle), and no message names a server path.
"""

from __future__ import annotations

import itertools
import os
import stat
import threading
import time
from pathlib import Path

MAX_NAME = 200  # characters of a name in the list (longer: not listed, refused)
KINDS = {
    "map": (".zarr", "a stability-map store"),
    "envelope": (".zarr", "a design-load envelope store"),
    "uncertainty": (".json", "an uncertainty result"),
    "verdict": (".json", "a result of the verdict under uncertainty"),
}
VERDICT_FORMAT = b'"format": "bogie-verdict-uncertainty-1"'  # what a verdict result starts with
MAX_RESULT_BYTES = 50_000_000  # an uncertainty result larger than this is not listed (not read)
MAX_INDEX_BYTES = 1_000_000  # a store's zarr.json larger than this is not read (not listed)


class StudyNameRefused(ValueError):
    """A name that is not an entry of the list (the same message for every reason)."""


def refusal(kind: str) -> str:
    """The one notice of a refused name of ``kind``."""
    return (f"that name is not {KINDS[kind][1]} in the server's studies folder — choose one "
            "from the list (↻ updates it)")


def plain_name(name) -> bool:
    """Whether ``name`` could name an entry directly inside a folder (no path, no NUL)."""
    return (isinstance(name, str) and 0 < len(name) <= MAX_NAME and "\x00" not in name
            and "/" not in name and "\\" not in name and not name.startswith(".")
            and (os.altsep is None or os.altsep not in name))


def _has_link(root: Path) -> bool:
    """Whether a symbolic link (or anything but folders and regular files) is inside ``root``."""
    for folder, folders, files in os.walk(root, followlinks=False):
        for entry in itertools.chain(folders, files):
            try:
                mode = os.lstat(os.path.join(folder, entry)).st_mode
            except FileNotFoundError:  # a chunk being written (a temporary file renamed away)
                continue
            if not (stat.S_ISDIR(mode) or stat.S_ISREG(mode)):
                return True
    return False


def _store_study(path: Path) -> str | None:
    """The ``study`` attribute of the Zarr store at ``path`` (a folder of the studies folder),
    None if it has none or its ``zarr.json`` is not a regular file that can be read (a link, a
    pipe, more than MAX_INDEX_BYTES)."""
    import json

    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path / "zarr.json", flags)  # no link followed, no pipe waited for
    except OSError:
        return None
    try:
        with os.fdopen(fd, "rb") as index:
            if not stat.S_ISREG(os.fstat(index.fileno()).st_mode):
                return None
            text = index.read(MAX_INDEX_BYTES + 1)
    except OSError:
        return None
    if len(text) > MAX_INDEX_BYTES:
        return None
    try:
        attributes = json.loads(text).get("attributes", {})
    except (ValueError, AttributeError):
        return None
    study = attributes.get("study") if isinstance(attributes, dict) else None
    return study if isinstance(study, str) else None


def _starts_as_verdict(path: Path) -> bool:
    """Whether the JSON file at ``path`` (a regular file) is a result of the verdict under
    uncertainty (``bogie assess --samples … --out``): its first bytes name the format."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags)
    except OSError:
        return False
    with os.fdopen(fd, "rb") as handle:
        return VERDICT_FORMAT in handle.read(256)


class StudiesFolder:
    """The operator's studies folder (created if missing)."""

    def __init__(self, root: str | Path):
        self.root = Path(root).expanduser()
        self._counter = itertools.count(1)
        self._lock = threading.Lock()

    def ensure(self) -> Path:
        """The folder, created if missing (its real path: links in the operator's path are
        resolved once)."""
        self.root.mkdir(parents=True, exist_ok=True)
        return self.root.resolve(strict=True)

    def _entry(self, name: str, kind: str) -> Path | None:
        """The path of ``name`` if it is a valid entry of ``kind`` now, else None."""
        suffix = KINDS[kind][0]
        if not plain_name(name) or not name.endswith(suffix) or name == suffix:
            return None
        root = self.ensure()
        path = root / name
        try:
            mode = os.lstat(path).st_mode
        except OSError:
            return None
        if kind in ("map", "envelope"):
            if not stat.S_ISDIR(mode):
                return None
            try:
                marker = os.lstat(path / "zarr.json").st_mode
            except OSError:
                return None
            if not stat.S_ISREG(marker):
                return None
            # an envelope store is listed as such, every other store as a map (the map view
            # says when a store is not one); then the walk through the store (the costly check)
            if (_store_study(path) == "envelope") != (kind == "envelope") or _has_link(path):
                return None
        elif not stat.S_ISREG(mode) or os.lstat(path).st_size > MAX_RESULT_BYTES:
            return None
        elif (kind == "verdict") != _starts_as_verdict(path):  # the two kinds of result files
            return None
        if path.resolve(strict=True).parent != root:
            return None
        return path

    def names(self, kind: str) -> list[str]:
        """The entries of ``kind`` a reviewer may pick, newest first."""
        root = self.ensure()
        found = []
        with os.scandir(root) as entries:
            for entry in entries:
                if self._entry(entry.name, kind) is not None:
                    found.append((entry.stat(follow_symlinks=False).st_mtime, entry.name))
        return [name for _, name in sorted(found, reverse=True)]

    def path(self, name, kind: str) -> Path:
        """The path of a listed entry (raises :class:`StudyNameRefused` otherwise)."""
        path = self._entry(name, kind) if isinstance(name, str) else None
        if path is None or name not in self.names(kind):
            raise StudyNameRefused(refusal(kind))
        return path

    def new_name(self, kind: str, prefix: str) -> str:
        """A fresh name of ``kind`` (``prefix-YYYYmmdd-HHMMSS-N``) not yet in the folder."""
        root = self.ensure()
        suffix = KINDS[kind][0]
        with self._lock:
            while True:
                name = f"{prefix}-{time.strftime('%Y%m%d-%H%M%S')}-{next(self._counter)}{suffix}"
                if not os.path.lexists(root / name):
                    return name
