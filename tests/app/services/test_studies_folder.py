"""The studies folder's listing while a store is being written (app/services/studies_folder.py).

The attacks on the folder (links, pipes, paths) are tested against a served app in
tests/app/server/test_boundary.py; here: a chunk file that Zarr renames away while the listing
walks the store does not empty the list.
"""

from __future__ import annotations

import os

from app.services import studies_folder
from app.services.studies_folder import StudiesFolder


def test_a_file_renamed_away_during_the_walk_does_not_hide_the_store(tmp_path, monkeypatch):
    store = tmp_path / "map-1.zarr"
    (store / "c").mkdir(parents=True)
    (store / "zarr.json").write_text('{"zarr_format": 3, "node_type": "group", '
                                     '"attributes": {"study": "map"}}', encoding="utf-8")
    (store / "c" / "0.partial").write_bytes(b"")
    real_lstat = os.lstat

    def lstat(path, *args, **kwargs):
        if str(path).endswith(".partial"):  # renamed by the writer between walk and lstat
            raise FileNotFoundError(2, "No such file or directory", str(path))
        return real_lstat(path, *args, **kwargs)

    monkeypatch.setattr(studies_folder.os, "lstat", lstat)
    assert not studies_folder._has_link(store)
    assert StudiesFolder(tmp_path).names("map") == ["map-1.zarr"]
