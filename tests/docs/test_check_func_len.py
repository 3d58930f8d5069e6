"""The function-length checker's own behaviour: what it counts as a C function and how long."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools"))
import check_func_len as c  # noqa: E402


def test_c_function_counted_from_name_to_closing_brace():
    src = "static int\nf(int a,\n  int b)\n{\n  return a + b;\n}\n"
    assert c.c_functions(src) == [("f", 2, 5)]


def test_c_initialisers_structs_and_literals_are_not_functions():
    src = (
        "struct s { int a; };\n"
        "static const int t[] = { 1, 2 };\n"
        "/* g(void) { */\n"
        'const char *x = "h(void) {";\n'
        "#define M(x) do { } while (0)\n"
        "void k(void) __attribute__((noreturn));\n"
        "void k(void) { for (;;) { } }\n"
    )
    assert c.c_functions(src) == [("k", 7, 1)]


def test_c_attribute_after_parameter_list():
    src = "void h(void) __attribute__((used))\n{\n}\n"
    assert c.c_functions(src) == [("h", 1, 3)]


def test_python_decorators_count():
    src = "@dec\ndef f():\n    return 1\n\n\nclass A:\n    def m(self):\n        pass\n"
    assert sorted(c.py_functions(src, "x.py")) == [("f", 1, 3), ("m", 7, 2)]


def test_every_violation_is_reported(tmp_path):
    d = tmp_path / "tools"
    d.mkdir()
    body = "\n".join("  x++;" for _ in range(10))
    (d / "a.c").write_text(f"void a(void)\n{{\n{body}\n}}\nvoid b(void)\n{{\n{body}\n}}\n")
    (d / "p.py").write_text("def p():\n" + "    x = 1\n" * 10)
    found = c.violations(str(tmp_path), ["tools"], 5)
    assert sorted((f[0], f[2]) for f in found) == [
        (os.path.join("tools", "a.c"), "a"),
        (os.path.join("tools", "a.c"), "b"),
        (os.path.join("tools", "p.py"), "p"),
    ]
