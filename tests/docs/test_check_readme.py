"""The README checker itself: an unmarked block, a skip without a reason and a failing
block each fail it; a marked, passing page passes; a write into a git tree is caught."""
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import check_readme  # noqa: E402


def _run(tmp_path, text, git=False):
    (tmp_path / "README.md").write_text(text)
    if git:
        subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
        (tmp_path / ".gitignore").write_text("out/\n")
    return check_readme.main(["--root", str(tmp_path)])


def test_unmarked_block_is_named(tmp_path, capsys):
    assert _run(tmp_path, "# t\n\n```sh\ntrue\n```\n") == 1
    assert "README.md:3: shell block has no readme-test mark" in capsys.readouterr().err


def test_skip_needs_reason(tmp_path):
    assert _run(tmp_path, "<!-- readme-test: skip: -->\n```sh\nfalse\n```\n") == 1


def test_run_short_needs_why(tmp_path):
    assert _run(tmp_path, "<!-- readme-test: run-short: true -->\n```sh\nfalse\n```\n") == 1


def test_marked_blocks(tmp_path):
    text = ("<!-- readme-test: run -->\n```sh\ntrue\n```\n\n"
            "```\noutput listing, not a command\n```\n"
            "<!-- readme-test: run-short: true\n     why: shorter -->\n```bash\nfalse\n```\n"
            "<!-- readme-test: skip: needs a board -->\n```sh\nfalse\n```\n")
    assert _run(tmp_path, text) == 0


def test_failing_block_fails(tmp_path, capsys):
    assert _run(tmp_path, "<!-- readme-test: run -->\n```sh\ntrue\nfalse\ntrue\n```\n") == 1
    assert "README.md:2: block failed" in capsys.readouterr().err


def test_background_job_is_stopped(tmp_path):
    assert _run(tmp_path, "<!-- readme-test: run -->\n```sh\nsleep 600 &\ntrue\n```\n") == 0


@pytest.mark.skipif(subprocess.run(["git", "--version"], capture_output=True).returncode != 0,
                    reason="git not installed")
def test_write_into_tree_is_caught(tmp_path, capsys):
    text = "<!-- readme-test: run -->\n```sh\nmkdir -p out && echo x > out/a && echo x > b.csv\n```\n"
    assert _run(tmp_path, text, git=True) == 1
    err = capsys.readouterr().err
    assert "b.csv" in err and "out/a" not in err


def test_replace_lines_edit_the_block(tmp_path, capsys):
    text = ("<!-- readme-test: run-short: replace: exit 3 => exit 0\n"
            "     why: shorter -->\n```sh\ntrue\nexit 3\n```\n")
    assert _run(tmp_path, text) == 0
    stale = text.replace("replace: exit 3", "replace: exit 4")
    assert _run(tmp_path, stale) == 1
    assert "'exit 4' is not in the block any more" in capsys.readouterr().out
