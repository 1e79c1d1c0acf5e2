"""Every command explains itself: what it does in one line, examples that work, options that tell the truth."""

from __future__ import annotations

import shlex

import pytest

from glsandbox import cli
from glsandbox.lesson import find_lesson
from glsandbox.measure.compare import build_variants

SUBCOMMANDS = sorted(cli.COMMANDS)


def help_text(capsys, *args: str) -> str:
    with pytest.raises(SystemExit) as stop:
        cli.main([*args, "--help"])
    assert stop.value.code == 0
    return capsys.readouterr().out


def test_every_subcommand_has_a_summary_and_examples() -> None:
    parser = cli.build_parser()
    (sub,) = [a for a in parser._actions if a.dest == "command"]
    assert sorted(sub.choices) == SUBCOMMANDS
    for name, (summary, examples) in cli.COMMANDS.items():
        assert summary and "\n" not in summary, name
        assert examples and all(e.startswith(f"glsandbox {name}") for e in examples), name


@pytest.mark.parametrize("name", SUBCOMMANDS)
def test_a_command_lines_parser_is_the_whole_parsers_subcommand(name: str) -> None:
    # main() builds only the subcommand a command line names (a cold start): the same
    # options, help and parse of its examples as the whole parser's.
    def subcommand(parser):
        (sub,) = [a for a in parser._actions if a.dest == "command"]
        return sub.choices

    whole, one = cli.build_parser(), cli.build_parser(name)
    assert list(subcommand(one)) == [name]
    assert subcommand(one)[name].format_help() == subcommand(whole)[name].format_help()
    for example in cli.COMMANDS[name][1]:
        words = shlex.split(example)[1:]
        assert vars(one.parse_args(words)) == vars(whole.parse_args(words))


@pytest.mark.parametrize("name", SUBCOMMANDS)
def test_subcommand_help_says_what_it_does_and_shows_examples(capsys, name: str) -> None:
    text = help_text(capsys, name)
    summary, examples = cli.COMMANDS[name]
    assert summary[:1].upper() + summary[1:] + "." in " ".join(text.split())
    tail = text.split("examples:\n", 1)[1]
    assert [line.strip() for line in tail.strip().splitlines()] == list(examples)


@pytest.mark.parametrize("example", [e for _, examples in cli.COMMANDS.values() for e in examples])
def test_every_example_parses_and_names_real_lessons(example: str) -> None:
    words = shlex.split(example)
    args = cli.build_parser().parse_args(words[1:])
    lesson = getattr(args, "lesson", None)
    if lesson and not lesson.endswith((".py", ".toml", "/")):
        cls = find_lesson(lesson)  # a built-in lesson: it exists
        cls.from_settings(getattr(args, "settings", []))  # and its --set values are accepted
        if args.command == "compare":
            build_variants(cls, args.vary, args.settings)


def test_the_top_level_help_lists_every_command_with_its_summary(capsys) -> None:
    text = "".join(help_text(capsys).split())  # argparse wraps lines (and after hyphens)
    for name, (summary, _) in cli.COMMANDS.items():
        assert "".join(f"{name} {summary}".split()) in text


def test_check_says_it_renders_at_the_references_size(capsys) -> None:
    text = " ".join(help_text(capsys, "check").split())
    assert "--size SIZE frame size WxH (default the reference's size)" in text
    assert "640x480" not in text


def test_tour_does_not_offer_set_which_it_cannot_take(capsys) -> None:
    assert "--set" not in help_text(capsys, "tour")


def test_tour_with_set_is_one_line_naming_it(capsys) -> None:
    with pytest.raises(SystemExit) as stop:
        cli.main(["tour", "--set", "time=1"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: glsandbox: unrecognized arguments: --set time=1")


def test_render_still_says_its_default_size(capsys) -> None:
    assert "frame size WxH (default 640x480)" in " ".join(help_text(capsys, "render").split())


def test_a_lesson_module_says_what_it_does_with_examples(capsys) -> None:
    with pytest.raises(SystemExit) as stop:
        cli.lesson_main(find_lesson("triangle"), ["--help"])
    assert stop.value.code == 0
    text = capsys.readouterr().out
    assert "opens it in a window, or renders it headless to a PNG." in " ".join(text.split())
    assert text.rstrip().endswith("examples:\n  python -m glsandbox.lessons.triangle\n"
                                  "  python -m glsandbox.lessons.triangle --headless --out triangle.png")
