"""gyroctl plot: chosen columns (telemetry or gyro-sim names) over a time window, each
axis labelled with its unit, a title naming the log; bad columns and windows refused."""
import pytest

from gyroctl_lib import cli, plot


def _csv(tmp_path, name="run.csv"):
    p = tmp_path / name
    rows = ["t_s,rate_dps,drive_amp,p_deg,flags,drive_amp_true_m"]
    rows += [f"{k / 100:.2f},{k * 0.1},{0.35},{25.0},1,1e-5" for k in range(200)]
    p.write_text("\n".join(rows) + "\n")
    return p


def test_columns_window_and_units(tmp_path, monkeypatch):
    import matplotlib.figure
    labels, titles, sizes = [], [], []
    orig = matplotlib.figure.Figure.savefig

    def spy(fig, *a, **k):
        for ax in fig.axes:
            labels.append(ax.get_ylabel())
            titles.append(ax.get_title())
            xs = ax.lines[0].get_xdata()
            assert min(xs) >= 0.5 and max(xs) <= 1.0
        sizes.append(tuple(fig.get_size_inches()))
        return orig(fig, *a, **k)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    out = tmp_path / "p.png"
    assert cli.main(["plot", str(_csv(tmp_path)), "--columns", "rate_dps,drive_amp_v,drive_amp_true_m,flags",
                     "--t-start", "0.5", "--t-end", "1.0", "--out", str(out)]) == 0
    assert labels == ["rate_dps [deg/s]", "drive_amp [V]", "drive_amp_true_m [m]", "flags"]
    assert titles[0].startswith("run: t = 0.500 to 1.000 s")
    assert sizes[0][1] < 10 and out.stat().st_size > 1000


def test_bad_requests_are_refused(tmp_path, capsys):
    c = str(_csv(tmp_path))
    assert cli.main(["plot", c, "--columns", "nope", "--out", str(tmp_path / "x.png")]) == 4
    assert "no column 'nope'" in capsys.readouterr().err
    assert cli.main(["plot", c, "--t-start", "5", "--out", str(tmp_path / "x.png")]) == 4
    assert "fewer than 2 rows" in capsys.readouterr().err
    with pytest.raises(plot.PlotError):
        plot.plot(str(tmp_path / "missing.csv"))
