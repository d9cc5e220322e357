"""bulge.run against `bulge run` on the demo experiment: the same tables, the
same numbers; a bad input's exception text against the command line's."""

import tomllib

import pandas as pd
import pytest

import bulge

pytestmark = pytest.mark.skipif(not bulge.HAS_OPENCV, reason="built without OpenCV")


@pytest.fixture(scope="module")
def demo(root, cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    p = cli("run", root / "data/demo/experiment.toml", "--out", out)
    # the demo's run is partial (exit 1: one model finds no equilibrium at
    # the top pressure) and still writes every file
    assert p.returncode in (0, 1) and (out / "simulated.csv").is_file(), p.stderr
    return out, bulge.run(root / "data/demo/experiment.toml")


@pytest.mark.parametrize(
    "name,attr",
    [
        ("heights.csv", "heights"),
        ("stress_strain.csv", "stress_strain"),
        ("simulated.csv", "simulated"),
    ],
)
def test_tables_equal_the_cli_csv(demo, name, attr):
    out, py = demo
    want = pd.read_csv(out / name)
    got = getattr(py, attr)
    assert list(got.columns) == list(want.columns)
    # wall_s is the solver's wall time: a measurement, not a result
    timing = [c for c in want.columns if c == "wall_s"]
    pd.testing.assert_frame_equal(got.drop(columns=timing), want.drop(columns=timing), check_exact=True)


def test_material_equals_the_cli_toml(demo):
    out, py = demo
    assert py.material == tomllib.loads((out / "material.toml").read_text())
    assert py.files["material.toml"] == (out / "material.toml").read_bytes()


def test_simulated_has_heights(demo):
    out, py = demo
    assert len(py.simulated) > 0
    # the pressures left unsolved are the ones the command line's notes name
    for p in py.unsolved:
        assert f"at {p:g} Pa" in cli_status(out)
    assert "pressure_pa" in py.simulated.columns


def cli_status(out):
    return "\n".join(p.read_text() for p in out.glob("*.md"))


def _cli_message(stderr):
    line = [l for l in stderr.splitlines() if l.startswith("error: ")]
    assert line, stderr
    return line[0][len("error: "):]


def test_missing_experiment_is_bad_input_with_the_cli_message(root, cli, tmp_path):
    missing = tmp_path / "nope.toml"
    p = cli("run", missing, "--out", tmp_path / "out")
    assert p.returncode == 2
    with pytest.raises(bulge.BadInput) as e:
        bulge.run(missing)
    assert isinstance(e.value, ValueError)
    assert str(e.value) == _cli_message(p.stderr)


def test_bad_value_is_bad_input_with_the_cli_message(root, cli, tmp_path):
    text = (root / "data/demo/experiment.toml").read_text()
    bad = tmp_path / "experiment.toml"
    bad.write_text(text.replace("thickness_m = 0.00035", "thickness_m = -0.00035"))
    p = cli("run", bad, "--out", tmp_path / "out")
    assert p.returncode == 2, p.stderr
    with pytest.raises(bulge.BadInput) as e:
        bulge.run(bad)
    assert str(e.value) == _cli_message(p.stderr)


def test_settings_as_keywords_equal_the_cli_flags(root, cli, tmp_path):
    exp = root / "data/demo/experiment.toml"
    p = cli("run", exp, "--fit", "mooney-rivlin", "--models", "tp", "--pressures", "1000,3000", "--out", tmp_path)
    assert p.returncode == 0, p.stderr
    seen = []
    py = bulge.run(
        exp, fit="mooney-rivlin", models=["tp"], pressures_pa=[1000, 3000], progress=lambda *a: seen.append(a)
    )
    # every stage told, in order, each from 0 to its total
    assert [a[0] for a in seen if a[1] == 0] == ["track", "stress", "fit", "simulate"]
    assert all(0 <= done <= total or total == 0 for _, done, total in seen)
    assert py.material == tomllib.loads((tmp_path / "material.toml").read_text())
    want = pd.read_csv(tmp_path / "simulated.csv")
    pd.testing.assert_frame_equal(py.simulated.drop(columns=["wall_s"]), want.drop(columns=["wall_s"]), check_exact=True)


def test_an_unknown_setting_is_bad_input_naming_it(root):
    with pytest.raises(bulge.BadInput, match="unknown field `fits`"):
        bulge.run(root / "data/demo/experiment.toml", fits="mooney-rivlin")
