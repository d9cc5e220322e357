"""bulge.track, bulge.stress and bulge.fit against `bulge track`, `bulge
stress` and `bulge fit` on the demo experiment and on Treloar's equibiaxial
data: the same tables and the same law; bad inputs raise BadInput with the
command line's message."""

import tomllib

import pandas as pd
import pytest

import bulge

opencv = pytest.mark.skipif(not bulge.HAS_OPENCV, reason="built without OpenCV")


def _cli_message(stderr):
    line = [l for l in stderr.splitlines() if l.startswith("error: ")]
    assert line, stderr
    return line[0][len("error: "):]


@pytest.fixture(scope="module")
def demo_cli(root, cli, tmp_path_factory):
    """`bulge track` then `bulge stress` on the demo, as files."""
    out = tmp_path_factory.mktemp("demo")
    exp = root / "data/demo/experiment.toml"
    p = cli("track", exp, "-o", out / "heights.csv")
    assert p.returncode == 0, p.stderr
    p = cli("stress", out / "heights.csv", "--experiment", exp, "-o", out / "stress_strain.csv")
    assert p.returncode == 0, p.stderr
    return out


@opencv
def test_track_equals_the_cli(root, demo_cli):
    seen = []
    t = bulge.track(root / "data/demo/experiment.toml", progress=lambda done, total: seen.append((done, total)))
    pd.testing.assert_frame_equal(t.heights, pd.read_csv(demo_cli / "heights.csv"), check_exact=True)
    assert t.skipped == []
    # the progress callback saw every frame once
    n = len(t.heights)
    assert sorted(d for d, _ in seen) == list(range(1, n + 1)) and {m for _, m in seen} == {n}


@opencv
def test_stress_of_a_dataframe_equals_the_cli(root, demo_cli):
    heights = pd.read_csv(demo_cli / "heights.csv")
    s = bulge.stress(heights, root / "data/demo/experiment.toml")
    want = pd.read_csv(demo_cli / "stress_strain.csv")
    pd.testing.assert_frame_equal(s.stress_strain, want, check_exact=True)
    assert "stress_pa" in s.stress_strain.columns and "strain_std" in s.stress_strain.columns


def test_stress_from_keywords_equals_the_cli_flags(root, cli, tmp_path):
    h = pd.DataFrame({"pressure_pa": [1000.0, 2000.0, 3000.0], "height_m": [0.008, 0.012, 0.0155]})
    h.to_csv(tmp_path / "h.csv", index=False)
    p = cli(
        "stress", tmp_path / "h.csv", "--radius-m", "0.0375", "--thickness-m", "0.00035",
        "--poisson", "0.45", "--strain", "log", "-o", tmp_path / "s.csv",
    )
    assert p.returncode == 0, p.stderr
    s = bulge.stress(h, radius_m=0.0375, thickness_m=0.00035, poisson=0.45, strain="log")
    pd.testing.assert_frame_equal(s.stress_strain, pd.read_csv(tmp_path / "s.csv"), check_exact=True)


def test_stress_of_a_bad_cell_is_bad_input_with_the_cli_message(cli, tmp_path):
    bad = tmp_path / "heights.csv"
    bad.write_text("pressure_pa,height_m\n1000,0.008\n2000,abc\n")
    flags = ["--radius-m", "0.0375", "--thickness-m", "0.00035", "--poisson", "0.45"]
    p = cli("stress", bad, *flags, "-o", tmp_path / "s.csv")
    assert p.returncode == 2, p.stderr
    with pytest.raises(bulge.BadInput) as e:
        bulge.stress(bad, radius_m=0.0375, thickness_m=0.00035, poisson=0.45)
    assert str(e.value) == _cli_message(p.stderr)
    # a DataFrame is named as such, with the line of the bad row
    with pytest.raises(bulge.BadInput, match=r"<heights DataFrame>.*line 3"):
        bulge.stress(pd.read_csv(bad, dtype=str), radius_m=0.0375, thickness_m=0.00035, poisson=0.45)


def test_stress_needs_the_specimen():
    h = pd.DataFrame({"pressure_pa": [1000.0], "height_m": [0.008]})
    with pytest.raises(bulge.BadInput, match="radius_m is required without experiment"):
        bulge.stress(h, thickness_m=0.00035, poisson=0.45)
    with pytest.raises(bulge.BadInput, match=r"strain=\"tru\""):
        bulge.stress(h, radius_m=0.0375, thickness_m=0.00035, poisson=0.45, strain="tru")


@pytest.mark.parametrize("model", ["mooney-rivlin", "quartic"])
def test_fit_equals_the_cli(root, cli, tmp_path, model):
    data = root / "data/treloar_equibiaxial.csv"
    p = cli("fit", data, "--model", model, "-o", tmp_path / "material.toml")
    assert p.returncode == 0, p.stderr
    f = bulge.fit(data, model=model)
    # given as a path, the material file is the command line's to the byte
    assert f.files["material.toml"] == (tmp_path / "material.toml").read_bytes()
    assert f.material == tomllib.loads((tmp_path / "material.toml").read_text())
    for name, attr in [("material_curve.csv", "curve"), ("material_residuals.csv", "residuals")]:
        pd.testing.assert_frame_equal(getattr(f, attr), pd.read_csv(tmp_path / name), check_exact=True)
        assert f.files[name] == (tmp_path / name).read_bytes()
    assert f.files["material_fit.svg"] == (tmp_path / "material_fit.svg").read_bytes()
    # from a DataFrame, the same law; only its source is named differently
    g = bulge.fit(pd.read_csv(data), model=model)
    assert g.material["fit"].pop("source") == "<stress_strain DataFrame>"
    assert f.material["fit"].pop("source") == str(data)
    assert g.material == f.material


@opencv
def test_fit_to_heights_equals_the_cli(root, cli, demo_cli, tmp_path):
    exp = root / "data/demo/experiment.toml"
    ss = demo_cli / "stress_strain.csv"
    p = cli("fit", ss, "--model", "neo-hookean", "--to-heights", exp, "-o", tmp_path / "material.toml")
    assert p.returncode == 0, p.stderr
    f = bulge.fit(ss, model="neo-hookean", to_heights=exp, plot=False)
    assert f.files["material.toml"] == (tmp_path / "material.toml").read_bytes()
    assert "corrected to the heights of" in f.summary
    assert "material_fit.svg" not in f.files


def test_fit_bad_choices_name_the_keyword(root):
    data = root / "data/treloar_equibiaxial.csv"
    with pytest.raises(bulge.BadInput, match=r"^poisson=0.5 is outside \[0, 0.5\)"):
        bulge.fit(data, poisson=0.5)
    with pytest.raises(bulge.BadInput, match=r"model=\"hooke\""):
        bulge.fit(data, model="hooke")


def test_fit_of_a_missing_file_is_bad_input_with_the_cli_message(cli, tmp_path):
    missing = tmp_path / "nope.csv"
    p = cli("fit", missing, "-o", tmp_path / "material.toml")
    assert p.returncode == 2
    with pytest.raises(bulge.BadInput) as e:
        bulge.fit(missing)
    assert str(e.value) == _cli_message(p.stderr)


def _drop_wall(df):
    # wall_s is the solver's wall time: a measurement, not a result
    return df.drop(columns=[c for c in df.columns if c == "wall_s"])


def test_simulate_a_scene_equals_the_cli(root, cli, tmp_path):
    scene = root / "data/scenes/latex-disc.toml"
    args = ["--model", "tp,axisym", "--nodes", "200"]
    p = cli("simulate", scene, *args, "--profile", tmp_path / "profile.csv", "-o", tmp_path / "sim.csv")
    assert p.returncode == 0, p.stderr
    seen = []
    s = bulge.simulate(scene=scene, model="tp,axisym", nodes=200, profile=True, progress=lambda d, n: seen.append(n))
    want = pd.read_csv(tmp_path / "sim.csv")
    pd.testing.assert_frame_equal(_drop_wall(s.simulated), _drop_wall(want), check_exact=True)
    pd.testing.assert_frame_equal(s.profile, pd.read_csv(tmp_path / "profile.csv"), check_exact=True)
    assert s.failures == [] and any(n.startswith("mesh: ") for n in s.notes)
    # two models at three pressures
    assert len(seen) == 6 and set(seen) == {6}


def test_simulate_a_fitted_law_on_the_experiment_equals_the_cli(root, cli, tmp_path):
    data = root / "data/treloar_equibiaxial.csv"
    assert cli("fit", data, "--model", "mooney-rivlin", "-o", tmp_path / "material.toml").returncode == 0
    exp = root / "data/demo/experiment.toml"
    p = cli(
        "simulate", "--experiment", exp, "--material", tmp_path / "material.toml",
        "--pressures", "1000,2000,3000", "--model", "axisym,van-gelder", "--nodes", "150",
        "-o", tmp_path / "sim.csv",
    )
    assert p.returncode == 0, p.stderr
    law = bulge.fit(data, model="mooney-rivlin", plot=False)
    for material in (law, law.material, tmp_path / "material.toml"):
        s = bulge.simulate(material, exp, pressures=[1000, 2000, 3000], model=["axisym", "van-gelder"], nodes=150)
        pd.testing.assert_frame_equal(_drop_wall(s.simulated), _drop_wall(pd.read_csv(tmp_path / "sim.csv")), check_exact=True)


def test_simulate_refuses_what_the_cli_refuses(root, cli, tmp_path):
    exp = root / "data/demo/experiment.toml"
    with pytest.raises(bulge.BadInput, match="experiment needs material"):
        bulge.simulate(experiment=exp, pressures=[1000])
    with pytest.raises(bulge.BadInput, match=r"model=\"tpp\""):
        bulge.simulate(scene=root / "data/scenes/latex-disc.toml", model="tpp")
    with pytest.raises(bulge.BadInput, match="<material dict>"):
        bulge.simulate({"model": "linear", "young_pa": -1.0, "poisson": 0.45}, exp, pressures=[1000])
    # a bad material file: the command line's message to the letter
    bad = tmp_path / "material.toml"
    bad.write_text('model = "neo-hookean"\nc1_pa = -5\npoisson = 0.45\n')
    p = cli("simulate", "--experiment", exp, "--material", bad, "--pressures", "1000", "-o", tmp_path / "s.csv")
    assert p.returncode == 2, p.stderr
    with pytest.raises(bulge.BadInput) as e:
        bulge.simulate(bad, exp, pressures=[1000])
    assert str(e.value) == _cli_message(p.stderr)


@opencv
def test_init_equals_the_cli(root, cli, tmp_path):
    photos, pressure = root / "data/demo/photos", root / "data/demo/pressure.csv"
    p = cli(
        "init", photos, "--radius-m", "0.0375", "--thickness-m", "0.00035",
        "--pressure", pressure, "-o", tmp_path / "experiment.toml",
    )
    assert p.returncode == 0, p.stderr
    out = bulge.init(photos, 0.0375, 0.00035, pressure=pressure, base=tmp_path)
    assert out.experiment_toml == (tmp_path / "experiment.toml").read_text()
    assert out.picture == (tmp_path / "init.png").read_bytes()
    assert out.summary in p.stdout
    # the file it gives is one bulge.track reads, its paths relative to base
    (tmp_path / "py").mkdir()
    there = bulge.init(photos, 0.0375, 0.00035, pressure=pressure, base=tmp_path / "py")
    (tmp_path / "py/experiment.toml").write_text(there.experiment_toml)
    t = bulge.track(tmp_path / "py/experiment.toml")
    assert len(t.heights) == len(list(photos.glob("*.jpg")))


@opencv
def test_init_takes_the_clamp_row_it_does_not_find(root, tmp_path):
    # a path-traced camera 8.31 degrees up: the ring's top face is a band
    # init does not choose an edge of; the ring centre's row given, it sets up
    src = root / "fixtures/track/raised_8deg"
    args = dict(pressure=src / "pressure.csv", camera=src / "camera.toml", base=tmp_path)
    with pytest.raises(bulge.BadInput, match=r"stripe.*`clamp_row_px`"):
        bulge.init(src / "photos", 0.0375, 0.00035, **args)
    out = bulge.init(src / "photos", 0.0375, 0.00035, elevation_deg=8.31, clamp_row_px=382.61, **args)
    assert out.experiment["calibration"]["clamp_row_px"] == 382.61
    assert out.experiment["calibration"]["elevation_deg"] == 8.31


@opencv
def test_init_refusals_name_the_keyword(root, cli, tmp_path):
    photos = root / "data/demo/photos"
    with pytest.raises(bulge.BadInput, match=r"^`elevation_deg` 45: give 0 to 30 degrees"):
        bulge.init(photos, 0.0375, 0.00035, elevation_deg=45)
    with pytest.raises(bulge.BadInput, match=r"^`every` applies to a video"):
        bulge.init(photos, 0.0375, 0.00035, every=2)
    with pytest.raises(bulge.BadInput, match=r"^`clamp_row_std_px` -1: give the clamp row's"):
        bulge.init(photos, 0.0375, 0.00035, clamp_row_px=384.4, clamp_row_std_px=-1)
    # the keyword, not the experiment file's key `[camera] distance_m`
    with pytest.raises(bulge.BadInput, match=r"^`camera_distance_m` 0.05: give the horizontal distance"):
        bulge.init(photos, 0.0375, 0.00035, camera_distance_m=0.05)
    missing = tmp_path / "nowhere"
    p = cli("init", missing, "--radius-m", "0.0375", "--thickness-m", "0.00035", "-o", tmp_path / "e.toml")
    assert p.returncode == 2
    with pytest.raises(bulge.BadInput) as e:
        bulge.init(missing, 0.0375, 0.00035)
    assert str(e.value) == _cli_message(p.stderr)


@opencv
def test_study_equals_the_cli(root, cli, tmp_path):
    """Two specimens with the demo's exact heights, the second 2 % thicker
    (a neo-Hookean law's pressure scales with C1 t)."""
    truth = pd.read_csv(root / "data/demo/truth.csv")
    truth[["pressure_pa", "height_m"]].to_csv(tmp_path / "heights.csv", index=False)
    inputs = []
    for name, t in [("a", 0.00035), ("b", 0.00035 * 1.02)]:
        (tmp_path / name).mkdir()
        inputs.append(tmp_path / name / "experiment.toml")
        inputs[-1].write_text(
            f'[specimen]\nradius_m = 0.0375\nthickness_m = {t}\npoisson = 0.45\n\n[heights]\ncsv = "../heights.csv"\n'
        )
    p = cli("study", *inputs, "--out", tmp_path / "cli", "--fit", "neo-hookean")
    assert p.returncode == 0, p.stderr
    seen = []
    s = bulge.study(inputs, tmp_path / "py", fit="neo-hookean", progress=lambda d, n: seen.append(d))
    want = pd.read_csv(tmp_path / "cli/study.csv")
    pd.testing.assert_frame_equal(s.study, want, check_exact=True)
    assert s.files["study.csv"] == (tmp_path / "cli/study.csv").read_bytes()
    assert (tmp_path / "py/specimens/a/study_fit.toml").is_file() and s.failed == []
    assert sorted(seen) == [1, 2]
    c1 = s.study.set_index(s.study.columns[0])["c1_pa"]
    assert abs(c1["b"] / (200e3 / 1.02) - 1) < 0.002
    # again into the same folder: both specimens read back, the same study
    again = bulge.study(inputs, tmp_path / "py", fit="neo-hookean")
    assert sum(line.startswith("  reused  ") for line in again.log) == 2
    pd.testing.assert_frame_equal(again.study, s.study, check_exact=True)


@opencv
def test_study_of_one_specimen_is_bad_input_with_the_cli_message(root, cli, tmp_path):
    p = cli("study", root / "data/demo/experiment.toml", "--out", tmp_path / "cli")
    assert p.returncode == 2, p.stderr
    with pytest.raises(bulge.BadInput) as e:
        bulge.study(root / "data/demo/experiment.toml", tmp_path / "py")
    assert str(e.value) == _cli_message(p.stderr)


DISC = """kind = "disc"
radius_m = 0.0375
thickness_m = 0.00035
pressure_pa = [5000]

[material]
model = "linear"
young_pa = 1.0e6
poisson = 0.45

[mesh]
nodes = 21
"""


def test_simulate_dynamic_equals_the_cli(cli, tmp_path):
    """A pressure step on a small disc, critically damped: Verlet and
    implicit Euler, the summary and the time histories as the command line
    writes them (but the wall time)."""
    scene = tmp_path / "scene.toml"
    scene.write_text(DISC)
    args = ["--integrator", "verlet,implicit-euler", "--t-end", "0.06", "--damping", "1"]
    p = cli("simulate", scene, "--dynamic", *args, "--trace", tmp_path / "trace.csv", "-o", tmp_path / "dyn.csv")
    assert p.returncode == 0, p.stderr
    s = bulge.simulate(scene=scene, dynamic=True, integrator="verlet,implicit-euler", t_end=0.06, damping=1)
    pd.testing.assert_frame_equal(_drop_wall(s.simulated), _drop_wall(pd.read_csv(tmp_path / "dyn.csv")), check_exact=True)
    pd.testing.assert_frame_equal(s.trace, pd.read_csv(tmp_path / "trace.csv"), check_exact=True)
    # settled to the static height within 0.5 %, as the command line's own test asks
    assert ((s.simulated.height_m / s.simulated.static_height_m - 1).abs() < 0.005).all()
    with pytest.raises(bulge.BadInput, match=r"`dynamic` needs `t_end`"):
        bulge.simulate(scene=scene, dynamic=True)
    with pytest.raises(bulge.BadInput, match=r"integrator=\"leapfrog\""):
        bulge.simulate(scene=scene, dynamic=True, integrator="leapfrog", t_end=0.01)
