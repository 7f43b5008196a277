"""The conventions users already know, on every command: -q/--quiet, --json where results are printed,
no silent overwrite of an -o file, a quiet end on a closed pipe, a warning for a channel that is not an
acceleration, and `simulate --noise-g`."""
import json
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from bearing_lab.cli import build_parser, main

#: commands whose result is printed: each takes --json
PRINTS_RESULTS = {"scenes", "simulate", "import", "info", "analyze", "validate", "case new", "case standin",
                  "identify", "data fetch", "data list", "data sample", "study", "sweep", "bench"}


def _leaves(parser, prefix=""):
    import argparse
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            for name, sub in a.choices.items():
                yield from _leaves(sub, f"{prefix} {name}".strip())
            return
    yield prefix, parser


def test_every_command_takes_quiet_and_the_printing_ones_json():
    leaves = dict(_leaves(build_parser()))
    assert PRINTS_RESULTS <= set(leaves)
    for name, p in leaves.items():
        opts = {o for a in p._actions for o in a.option_strings}
        assert {"-q", "--quiet"} <= opts, name
        if name in PRINTS_RESULTS:
            assert "--json" in opts, name


def test_a_command_alone_parses_as_in_the_whole_command_line():
    """main() builds only the named command's module (COMMANDS): the table names every command, and
    each command's parser built alone has the same options as in the whole command line."""
    import argparse
    from bearing_lab.cli import COMMANDS
    whole = dict(_leaves(build_parser()))
    tops = {name.split()[0] for name in whole}
    assert set(COMMANDS) == tops
    for command in COMMANDS:
        alone = dict(_leaves(build_parser(command)))
        mine = {k: p for k, p in whole.items() if k.split()[0] == command}
        assert set(mine) <= set(alone), command
        for k, p in mine.items():
            assert ([a.option_strings for a in p._actions if not isinstance(a, argparse._SubParsersAction)]
                    == [a.option_strings for a in alone[k]._actions if not isinstance(a, argparse._SubParsersAction)]), k
    # a name that is no command gets the whole command line and its one-line error
    with pytest.raises(SystemExit) as e:
        build_parser("simulat").parse_args(["simulat"])
    assert e.value.code == 2


def test_simulate_quiet_is_silent_and_an_existing_output_is_kept(tmp_path, capfd):
    out = tmp_path / "s.nc"
    args = ["simulate", "paper-healthy", "--duration", "0.05", "-o", str(out)]
    assert main(args + ["-q"]) == 0
    assert capfd.readouterr() == ("", "")
    before = out.read_bytes()
    assert main(args + ["-q"]) == 2
    assert "exists; pass --force to overwrite it" in capfd.readouterr().err
    assert out.read_bytes() == before
    assert main(args + ["--force", "--json", "--noise-g", "0.1"]) == 0
    got = json.loads(capfd.readouterr().out)
    assert got["noise"] == {"rms_g": 0.1, "color": "white", "seed": 0, "channel": "outer_ring_acc_y"}


def test_noise_is_seeded_scaled_and_recorded():
    from bearing_lab.sim.noise import add_measurement_noise
    t = np.arange(40000) / 20000.0
    ds = xr.Dataset({"outer_ring_acc_y": ("time", np.sin(2 * np.pi * 90 * t), {"units": "m s-2"})},
                    coords={"time": t}, attrs={"default_channel": "outer_ring_acc_y"})
    for color in ("white", "pink", "brown"):
        a = add_measurement_noise(ds, 0.2, seed=3, color=color)
        n = a["outer_ring_acc_y"].values - ds["outer_ring_acc_y"].values
        assert np.sqrt(np.mean(n ** 2)) == pytest.approx(0.2 * 9.80665, rel=0.05 if color == "white" else 1e-9)
        assert a.attrs["measurement_noise_g"] == 0.2 and a.attrs["measurement_noise_color"] == color
        assert a.attrs["measurement_noise_seed"] == 3 and a["outer_ring_acc_y"].attrs["measurement_noise_g"] == 0.2
        np.testing.assert_array_equal(a["outer_ring_acc_y"].values,
                                      add_measurement_noise(ds, 0.2, seed=3, color=color)["outer_ring_acc_y"].values)
        assert not np.array_equal(n, add_measurement_noise(ds, 0.2, seed=4, color=color)["outer_ring_acc_y"].values
                                  - ds["outer_ring_acc_y"].values)
        spec = np.abs(np.fft.rfft(n)) ** 2
        low, high = spec[20:200].mean(), spec[-2000:].mean()   # white: flat; pink, brown: falling
        assert (0.7 < low / high < 1.4) if color == "white" else low / high > 30
    assert add_measurement_noise(ds, 0.0) is ds and "measurement_noise_g" not in ds.attrs


def test_a_closed_pipe_ends_quietly():
    """`bearing-lab data list | head`: the reader has gone before we write (deterministic: its end is closed)."""
    import os
    r, w = os.pipe()
    os.close(r)
    p = subprocess.run([sys.executable, "-m", "bearing_lab", "data", "list"], stdout=w, stderr=subprocess.PIPE,
                       timeout=60)
    os.close(w)
    assert p.stderr.decode() == "" and p.returncode == 141


def test_data_list_json(capsys):
    assert main(["data", "list", "--dataset", "cwru", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert rows and all(r["dataset"].startswith("cwru") for r in rows) and "130_OR007@6_0.mat" in \
        " ".join(r["name"] for r in rows)


def test_a_microphone_channel_is_said_not_to_be_an_acceleration(tmp_path, capsys):
    t = np.arange(20000) / 20000.0
    x = 0.5 * np.sin(2 * np.pi * 100 * t) + 0.05 * np.random.default_rng(0).normal(size=t.size)
    p = tmp_path / "mic.csv"
    p.write_text("time,mic [Pa]\n" + "\n".join(f"{a:.8f},{b:.9g}" for a, b in zip(t, x)) + "\n")
    assert main(["analyze", str(p), "--bearing", "6205", "--rpm", "1800", "--json"]) == 0
    out = capsys.readouterr()
    assert "is a sound pressure (a microphone), not an acceleration" in out.err
    assert any("not an acceleration" in n for n in json.loads(out.out)["notes"])
    acc = tmp_path / "acc.csv"
    acc.write_text(p.read_text().replace("mic [Pa]", "acc [m/s2]"))
    assert main(["analyze", str(acc), "--bearing", "6205", "--rpm", "1800", "-q"]) == 0
    assert capsys.readouterr() == ("", "")


def test_import_and_standin_keep_an_existing_output(tmp_path, capsys):
    from bearing_lab.io._testing import uff58_block
    src = tmp_path / "v.uff"
    src.write_bytes(uff58_block(np.sin(np.arange(1000) / 10.0), unit="g", spec=1))
    out = tmp_path / "v.nc"
    assert main(["import", str(src), "-o", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["output"] == str(out)
    assert main(["import", str(src), "-o", str(out)]) == 2
    assert "exists; pass --force" in capsys.readouterr().err
    assert main(["import", str(src), "-o", str(out), "--force", "-q"]) == 0
    assert capsys.readouterr() == ("", "")
    assert main(["case", "standin", "paper-O2", "-o", str(src)]) == 2      # refused before any simulation
    assert "exists; pass --force" in capsys.readouterr().err


def test_analyze_states_evidence_in_lines_and_db_not_summed_db(datafile, capsys):
    """No '282 dB' for a sum of line SNRs: lines and their mean line-to-floor ratio; the sum is a score."""
    import re
    rec = datafile("cwru/130_OR007@6_0.mat")
    assert main(["analyze", str(rec), "--bearing", "6205", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    ev = d["evidence"]
    lead = ev["routes"][ev["reported_route"]]["families"]["bpfo"]
    assert lead["n_lines"] * lead["mean_line_snr_db"] == pytest.approx(lead["evidence_score"])
    assert ev["leader_lines"] == {"n_lines": lead["n_lines"], "mean_line_snr_db": lead["mean_line_snr_db"]}
    assert not any(k.endswith("_db") and "evidence" in k for k in lead)
    assert main(["analyze", str(rec), "--bearing", "6205"]) == 0
    text = capsys.readouterr().out
    assert "runner-up: inner_race (envelope-spectrum lines over the floor:" in text
    assert max(float(v) for v in re.findall(r"([\d.]+) dB", text)) <= 60.0, text   # a line SNR is capped at 60 dB


def test_the_collector_is_left_alone_inside_another_program_and_set_aside_in_the_own_process(tmp_path):
    """main(argv) called by a program (a test, a notebook) leaves the garbage collector as it was; the
    process's own command line (the console script) sets its long-lived objects aside (gc.freeze), and
    the file it writes is whole."""
    import gc
    before = gc.get_freeze_count()
    assert main(["scenes", "-q"]) == 0
    assert gc.get_freeze_count() == before
    out = tmp_path / "a.nc"
    code = ("import gc, sys\nfrom bearing_lab.cli import main\n"
            f"sys.argv = ['bearing-lab', 'simulate', 'paper-healthy', '--duration', '0.01', '-q', '-o', {str(out)!r}]\n"
            "status = main()\nprint(status, gc.get_freeze_count() > 10000)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert res.stdout.split() == ["0", "True"]
    ds = xr.load_dataset(out)
    assert ds.sizes["time"] > 0 and np.all(np.isfinite(ds["outer_ring_acc_y"].values))
