"""Saving a watched file is seen once, at the next look after the interval; new files are not changes."""

from __future__ import annotations

import os
from pathlib import Path

from glsandbox.app.file_watch import FileWatch, stamp


def test_stamp_is_time_and_size_or_none_while_missing(tmp_path: Path) -> None:
    path = tmp_path / "a.glsl"
    assert stamp(path) is None
    path.write_text("abc")
    assert stamp(path) == (os.stat(path).st_mtime_ns, 3)


def test_a_save_is_reported_once_and_only_after_the_interval(tmp_path: Path) -> None:
    path = tmp_path / "a.glsl"
    path.write_text("one")
    watch = FileWatch(lambda: [path], interval=0.25)
    assert not watch.changed(now=10.0)  # first seen: recorded, not reported
    path.write_text("two!")  # a new size, whatever the clock's resolution
    assert not watch.changed(now=10.1)  # within the interval: the disk is not looked at
    assert watch.changed(now=10.3)
    assert not watch.changed(now=10.6)  # reported once


def test_a_file_deleted_then_written_again_is_a_change_each_time(tmp_path: Path) -> None:
    path = tmp_path / "lesson.toml"
    path.write_text("a")
    watch = FileWatch(lambda: [path], interval=0.0)
    assert not watch.changed(now=1.0)
    path.unlink()  # an editor between deleting and writing
    assert watch.changed(now=2.0)
    path.write_text("ab")
    assert watch.changed(now=3.0)


def test_the_file_list_is_asked_each_look_and_a_new_file_is_not_a_change(tmp_path: Path) -> None:
    files = [tmp_path / "a.glsl"]
    files[0].write_text("a")
    watch = FileWatch(lambda: list(files), interval=0.0)
    assert not watch.changed(now=1.0)
    files.append(tmp_path / "b.glsl")
    files[1].write_text("b")
    assert not watch.changed(now=2.0)
    files[1].write_text("bb")
    assert watch.changed(now=3.0)
