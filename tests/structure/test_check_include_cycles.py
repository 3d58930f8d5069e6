"""The include-cycle check catches what it is for: a cycle between two files, a cycle
between two folders (through files that are not themselves in a cycle), and it passes a
tree whose dependencies run one way."""
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import check_include_cycles as chk  # noqa: E402


def tree(tmp_path, files):
    for rel, text in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return str(tmp_path)


def run(root, capsys):
    rc = chk.main(["--root", root])
    return rc, capsys.readouterr().out


def test_one_way_passes(tmp_path, capsys):
    root = tree(tmp_path, {
        "firmware/comm/cli.h": '#include "params/params.h"\n',
        "firmware/comm/cli.c": '#include "comm/cli.h"\n',
        "firmware/comm/cli_builtin.c": '#include "comm/cli.h"\n',
        "firmware/params/params.h": "",
        "hal/include/hal/hal_uart.h": "",
        "hal/host/hal_uart_host.c": '#include "hal/hal_uart.h"\n',
    })
    rc, out = run(root, capsys)
    assert rc == 0, out


def test_file_cycle_fails(tmp_path, capsys):
    root = tree(tmp_path, {
        "firmware/comm/cli.h": "",
        "firmware/comm/cli.c": '#include "comm/cli.h"\n#include "comm/cli_builtin.h"\n',
        "firmware/comm/cli_builtin.h": "",
        "firmware/comm/cli_builtin.c": '#include "comm/cli.h"\n',
        "hal/include/hal/hal_uart.h": "",
    })
    rc, out = run(root, capsys)
    assert rc == 1
    assert "file cycle" in out and "firmware/comm/cli_builtin" in out


def test_folder_cycle_fails(tmp_path, capsys):
    root = tree(tmp_path, {
        "firmware/gyro/gyro.h": '#include "params/params.h"\n',
        "firmware/params/params.h": "",
        "firmware/params/store.c": '#include "gyro/version.h"\n',
        "firmware/gyro/version.h": "",
        "hal/include/hal/hal_uart.h": "",
    })
    rc, out = run(root, capsys)
    assert rc == 1
    assert "folder cycle" in out and "file cycle" not in out
