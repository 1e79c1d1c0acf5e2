"""glsandbox.files: atomic writes with unique temporary names, long names, stale leftovers."""

from __future__ import annotations

import os
import threading
import time

import numpy as np
import pytest

from glsandbox import files


def test_png_round_trip_and_no_temporary_left(tmp_path):
    image = np.arange(4 * 5 * 4, dtype=np.uint8).reshape(4, 5, 4)
    path = files.save_png(image, tmp_path / "sub" / "a.png")
    np.testing.assert_array_equal(files.load_png(path), image)
    assert sorted(p.name for p in path.parent.iterdir()) == ["a.png"]


def test_a_failing_writer_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "report.md"
    files.write_text(target, "old")

    def broken(f):
        f.write(b"half")
        raise RuntimeError("disk on fire")

    with pytest.raises(RuntimeError):
        files.atomic_write(target, broken)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["report.md"]


def test_concurrent_writers_of_one_name_never_expose_half_a_file(tmp_path):
    target = tmp_path / "tour.json"
    texts = [("x" * 200_000 + str(i)) for i in range(2)]
    errors: list[BaseException] = []

    def write(text: str) -> None:
        try:
            for _ in range(20):
                files.write_text(target, text)
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=write, args=(t,)) for t in texts]
    for t in threads:
        t.start()
    seen = set()
    while any(t.is_alive() for t in threads):
        if target.exists():
            seen.add(target.read_text())
    for t in threads:
        t.join()
    assert not errors
    assert seen <= set(texts)
    assert [p.name for p in tmp_path.iterdir()] == ["tour.json"]


def test_the_longest_legal_name_can_be_written(tmp_path):
    name = "n" * 250 + ".png"  # 254 bytes: legal, and longer than any temporary name with it in full
    path = files.save_png(np.zeros((2, 2, 4), np.uint8), tmp_path / name)
    assert path.exists() and [p.name for p in tmp_path.iterdir()] == [name]


def test_stale_temporaries_of_a_killed_writer_are_removed_fresh_ones_kept(tmp_path):
    stale = tmp_path / ".a.png.abcd1234.tmp"
    fresh = tmp_path / ".a.png.wxyz9876.tmp"
    other = tmp_path / ".b.png.abcd1234.tmp"
    for p in (stale, fresh, other):
        p.write_bytes(b"partial")
    old = time.time() - files.STALE_SECONDS - 5
    os.utime(stale, (old, old))
    os.utime(other, (old, old))
    files.save_png(np.zeros((2, 2, 4), np.uint8), tmp_path / "a.png")
    assert not stale.exists()
    assert fresh.exists() and other.exists()  # a live writer's file, and another name's


def test_next_numbered_continues_after_the_highest_file_there(tmp_path: Path) -> None:
    from glsandbox.files import next_numbered

    assert next_numbered(tmp_path, "cube") == tmp_path / "cube-1.png"
    for name in ("cube-1.png", "cube-7.png", "cube-x.png", "cube-2.jpg", "cubes-9.png", "[cube]-4.png"):
        (tmp_path / name).write_bytes(b"")
    assert next_numbered(tmp_path, "cube") == tmp_path / "cube-8.png"
    assert next_numbered(tmp_path, "[cube]") == tmp_path / "[cube]-5.png"  # glob characters in the name
