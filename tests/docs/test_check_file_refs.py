"""The file-reference checker's own behaviour: which names it reads as files of the tree."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools"))
import check_file_refs as c  # noqa: E402


def make_tree(tmp_path, files):
    for rel, text in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return str(tmp_path)


def names(misses):
    return sorted((m[0], m[2]) for m in misses)


def test_missing_files_in_comments_and_documents(tmp_path):
    root = make_tree(tmp_path, {
        "fw/a.h": "/* see b.h and gone.h; architecture.md */\nint x; /* fw/b.h */\n",
        "fw/b.h": "// fw/missing.c\n",
        "docs/page.md": "Read `fw/a.h`, `docs/nope.md` and glossary.md.\n",
        "tools/t.py": '"""Writes docs/page.md from fw/none.h."""\n# tools/absent.py\nx = "z.h"\n',
        "CMakeLists.txt": "# fw/*.h are the headers; fw/*.cpp none\n",
    })
    assert names(c.check(root)) == [
        ("CMakeLists.txt", "fw/*.cpp"),
        ("docs/page.md", "docs/nope.md"),
        ("docs/page.md", "glossary.md"),
        ("fw/a.h", "architecture.md"),
        ("fw/a.h", "gone.h"),
        ("fw/b.h", "fw/missing.c"),
        ("tools/t.py", "fw/none.h"),
        ("tools/t.py", "tools/absent.py"),
    ]


def test_what_is_not_a_file_of_the_tree(tmp_path):
    root = make_tree(tmp_path, {
        "fw/mech.c": "",
        "fw/sub/x.h": "",
        "fw/a.c": (
            "#include <stdio.h>\n"
            "/* fw/mech (the module), sub/x.h relative, out/report/index.md written by a\n"
            " * tool, fw/NAME.json a placeholder, https://example.org/y/z.h a URL,\n"
            " * trace.csv an output */\n"
            'const char *s = "fw/not_in_a_comment.h";\n'
        ),
    })
    assert c.check(root) == []


def test_line_numbers(tmp_path):
    root = make_tree(tmp_path, {"a.c": "int a;\n/* one\n * two gone.h\n */\n"})
    assert c.check(root) == [("a.c", 3, "gone.h")]
