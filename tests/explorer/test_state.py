"""The explorer's state and computations without a browser: links, validation, caps, eigenvalues, audio."""

from __future__ import annotations

import wave

import numpy as np
import pytest

from brakesqueal import ParameterError, linearize, resolve_space
from brakesqueal.analysis.linear import state_matrix
from brakesqueal.cli import main
from brakesqueal.explorer.state import (
    MAX_MAP_POINTS,
    Origin,
    ViewState,
    audio_samples,
    check_map_size,
    check_t_end,
    format_eigenvalue,
    leading_eigenvalue,
    locus_lines,
    locus_view,
    slider_range,
)


@pytest.fixture(scope="module")
def origin():
    return Origin(resolve_space(None, None, None, ["mu=0.4"]))


def test_link_round_trip(origin):
    st = origin.initial_state()
    assert (st.model, st.preset, dict(st.values)) == ("paper", "paper-fig2", {"mu": "0.4"})
    assert (st.along, st.x, st.y) == ("mu", "k_ip", "mu")
    back = ViewState.from_query(st.to_query(), ViewState("belt", "belt"))
    assert back == st
    assert origin.space_of(back).resolve({})["mu1"] == 0.4


def test_link_validates_like_the_command_line(origin):
    st = origin.initial_state()
    with pytest.raises(ParameterError, match="mu1"):
        origin.space_of(st.with_values({"mu": "-1"}))
    with pytest.raises(ParameterError, match="not defined in preset"):
        origin.space_of(st.with_values({"nope": "1"}))
    with pytest.raises(ParameterError, match="malformed set entry"):
        ViewState.from_query({"set": "mu"}, st)


def test_link_cannot_make_the_server_read_files(origin):
    with pytest.raises(ParameterError, match="unknown model '/etc/passwd'"):
        origin.space_of(ViewState("/etc/passwd", ""))


def test_caps_have_clear_messages():
    check_map_size(1000, 1000)
    with pytest.raises(ParameterError, match=f"at most {MAX_MAP_POINTS:,} points"):
        check_map_size(1001, 1000)
    with pytest.raises(ParameterError, match=r"t_end = 10 s: must be in \(0, 5\] s"):
        check_t_end(10)
    with pytest.raises(ParameterError, match="t_end"):
        check_t_end(float("nan"))


def test_slider_range_avoids_invalid_ends(origin):
    space = origin.space
    rng = slider_range(space, "mu")  # N0 = 1800/mu: mu = 0 is invalid
    assert rng.low > 0 and not rng.log
    space.resolve({"mu": rng.low})
    k = slider_range(space, "k_ip")
    assert k.log and k.low == pytest.approx(1e6) and k.high == pytest.approx(1e10)
    assert k.from_slider(k.to_slider(3e7)) == pytest.approx(3e7)


def test_leading_eigenvalue_is_the_state_matrix_one(origin):
    space = origin.space
    lv = locus_view(space, "mu", slider_range(space, "mu"), num=10)
    lm = linearize(space.resolve({}))
    lam = np.linalg.eigvals(state_matrix(lm.M, lm.D, lm.K))  # an independent eigen-solve
    ref = lam[np.argmax(lam.real + 1e-9 * np.sign(lam.imag))]
    assert lv.leading.real == pytest.approx(ref.real, rel=1e-6, abs=1e-9)
    assert lv.leading.imag == pytest.approx(abs(ref.imag), rel=1e-9)
    assert lv.tracks.eigenvalues.shape == (10, 2)
    assert leading_eigenvalue([1 - 2j, 1 + 2j, -3]) == 1 + 2j
    assert format_eigenvalue(0.1838688 + 10927.157j) == "0.183869 + 10927.2i"


def test_locus_lines_hold_every_mode_between_nans(origin):
    space = origin.space
    tr = locus_view(space, "mu", slider_range(space, "mu"), num=7).tracks
    lines = locus_lines(tr.values, tr.eigenvalues)
    n, m = tr.eigenvalues.shape
    assert {k: v.dtype for k, v in lines.items()} == dict.fromkeys(("value", "re", "im", "freq"), np.float64)
    gaps = np.flatnonzero(np.isnan(lines["re"]))
    assert list(gaps) == [k * (n + 1) + n for k in range(m - 1)]
    for k, seg in enumerate(np.split(np.arange(lines["re"].size), gaps)):
        seg = seg[~np.isin(seg, gaps)]
        lam = np.array([tr.eigenvalues[i][k] for i in range(n)])  # mode k, point by point
        assert np.array_equal(lines["re"][seg], lam.real) and np.array_equal(lines["im"][seg], lam.imag)
        assert np.array_equal(lines["value"][seg], np.asarray(tr.values, dtype=float))
        assert np.allclose(lines["freq"][seg], [abs(z.imag) / (2 * np.pi) for z in lam], rtol=1e-15)
    assert all(v.size == 0 for v in locus_lines(np.empty(0), np.empty((0, 0))).values())


@pytest.mark.slow
def test_audio_equals_the_wav_file(tmp_path):
    from brakesqueal import simulate

    tr = simulate(resolve_space(None, None, None, ["mu=1"]).resolve({}), 0.02)
    pcm = audio_samples(tr.audio_velocity()[0])
    frames = tr.to_wav(str(tmp_path / "a.wav"))
    with wave.open(str(tmp_path / "a.wav")) as w:
        data = np.frombuffer(w.readframes(frames), dtype="<i2")
    assert pcm.size == frames == tr.t.size
    assert np.array_equal(pcm, data)


def test_cli_refuses_bad_input_with_status_2(capsys):
    assert main(["explore", "--set", "mu=-1", "--no-browser"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "mu1" in err
    assert main(["explore", "--port", "70000", "--no-browser"]) == 2


@pytest.mark.slow
def test_non_loopback_host_with_allow_remote_warns():
    # without --allow-remote it is refused (tests/explorer/test_server_security.py)
    import subprocess
    import sys

    pytest.importorskip("panel")
    proc = subprocess.Popen([sys.executable, "-m", "brakesqueal", "explore", "--host", "0.0.0.0", "--allow-remote",
                             "--port", "0", "--no-browser"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    lines: list[str] = []
    try:
        while len(lines) < 10 and not (lines and "explorer at" in lines[-1]):
            lines.append(proc.stderr.readline())
    finally:
        proc.terminate()
        proc.wait(10)
    assert lines[0].startswith("brakesqueal: warning: serving on 0.0.0.0, not loopback")
    assert lines[-1].startswith("brakesqueal: explorer at http://127.0.0.1:") and "/?token=" in lines[-1]


def test_hopf_line_names_the_predicted_lift_off_and_drops_the_amplitude_beyond_it():
    # found in review: at mu = 0.5 the line gave an amplitude "here" although `brakesqueal hopf` predicts the
    # pads lift off at mu = 0.41027, beyond which the normal form of the bilateral equations does not hold
    from brakesqueal import Axis
    from brakesqueal.explorer.state import SliderRange, hopf_scan, hopf_text
    from brakesqueal import hopf_points

    space = resolve_space(None, "paper-fig2", None, [])
    rng = SliderRange(0.01, 1.0, False)
    pts = hopf_scan(space, "mu", rng)
    ref = next(h for h in hopf_points(space, Axis("mu", 0.01, 1.0, 2)) if h.hopf is not None)
    assert ref.contact_loss is not None and ref.hopf.p0 < ref.contact_loss < 0.5
    near = hopf_text(pts, "mu", 0.5 * (ref.hopf.p0 + ref.contact_loss), rng)
    far = hopf_text(pts, "mu", 0.5, rng)
    assert " here" in near and "does not hold" not in near and f"{ref.contact_loss:.6g}" in near
    assert "does not hold here" in far and " = " not in far.split("sqrt(")[1].split(";")[0]


def test_critical_speed_line_says_unstable_at_start(tmp_path):
    # the docs' caliper-stribeck model is unstable below 18.0 rad/s, then stable up to its Omega_crit = 34.92
    # (review: the line read "Omega_crit = 34.9196" with no word of the instability below)
    import re
    from pathlib import Path

    from brakesqueal import critical_speeds
    from brakesqueal.explorer.state import critical_speed_text
    from brakesqueal.model import load_model

    text = Path(__file__).resolve().parents[2].joinpath("docs", "model-format.md").read_text()
    f = tmp_path / "caliper.toml"
    f.write_text(re.search(r"```toml\n(.*?caliper-stribeck.*?)```", text, re.S).group(1))
    space = resolve_space(load_model(f), None, None, [])
    r = critical_speeds(space)
    assert not r.stable_at_start and r.crossings[0][1] == "stabilizing"
    line = critical_speed_text(space)
    assert line.startswith("critical speed: unstable at 1 rad/s; ")
    stable = critical_speed_text(resolve_space(None, "paper-fig3", None, []))
    assert "unstable at" not in stable


@pytest.mark.parametrize("text, expect", [
    ("nan", "d_t = nan: not a number"),
    ("1e999", "d_t = 1e999: the number overflows"),
    ("", "d_t: enter a number or an expression"),
    ("abc", "value of 'd_t' = abc: unknown name 'abc'"),
    ("-1", "The parameter 'd_t'"),
])
def test_page_messages_name_the_field_not_command_line_options(origin, text, expect):
    """A value typed into the page is named by its parameter; the command line's ``--set`` is not mentioned."""
    with pytest.raises(ParameterError) as excinfo:
        origin.space_of(origin.initial_state().with_values({"d_t": text}))
    message = str(excinfo.value)
    assert message.startswith(expect) and "--set" not in message and "\n" not in message
    assert excinfo.value.parameter == "d_t"


def test_default_axes_pass_over_names_the_verdict_cannot_depend_on():
    """The belt's zero-state M = m, D = d_ip - N0 slope, K = k_ip (``brakesqueal derive --model belt``) hold neither
    the disk's thickness, Omega, r nor mu0: the default map's axes are names the verdict depends on, and its map
    holds both verdicts (the first two free names, h10/h20, gave a map unstable everywhere)."""
    from brakesqueal.explorer.state import default_axes, map_view, stability_names

    space = resolve_space("belt", None, None, [])
    names = stability_names(space, list(space.preset.free))
    assert not {"h10", "h20", "Omega", "r", "mu0"} & set(names)
    assert {"N0", "d_ip", "slope"} <= set(names)
    along, x, y = default_axes(space)
    assert along == y and {x, y} <= set(names)
    mv = map_view(space, x, y, slider_range(space, x), slider_range(space, y), 20, 20)
    assert 0.05 < mv.stable[mv.status <= 1].mean() < 0.95
    # a preset's two free names stay the axes (Fig. 2)
    assert default_axes(resolve_space(None, "paper-fig2", None, [])) == ("mu", "k_ip", "mu")
