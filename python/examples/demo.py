"""The demo experiment from Python, stage by stage and whole: set it up
from its photos, track them, stress and strain, Mooney-Rivlin fitted and corrected to the
heights, then bulge.run, and the measured heights with their 95 % band
(1.96 x height_std_m) beside each model's simulated heights.
Run from anywhere: python python/examples/demo.py (matplotlib optional:
without it the tables are printed only)."""

import pathlib

import bulge

root = pathlib.Path(__file__).resolve().parents[2]
experiment = root / "data/demo/experiment.toml"

setup = bulge.init(root / "data/demo/photos", 0.0375, 0.00035, pressure=root / "data/demo/pressure.csv", base=root / "data/demo")
print(setup.summary)

tracked = bulge.track(experiment, progress=lambda done, total: print(f"\rtrack {done}/{total}", end=""))
print()
print(tracked.heights[["file", "pressure_pa", "height_m", "height_std_m"]])

stress = bulge.stress(tracked.heights, experiment)
print(stress.stress_strain[["pressure_pa", "strain", "stress_pa", "stress_std_pa"]])

law = bulge.fit(stress.stress_strain, model="mooney-rivlin", to_heights=experiment, plot=False)
print(law.summary)

sim = bulge.simulate(law, experiment, pressures=tracked.heights.pressure_pa, model="axisym,tp", nodes=300)
print(sim.simulated[["pressure_pa", "height_m", "model"]])

out = bulge.run(experiment)
print(out.material)
print(out.simulated)

try:
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no figure (pip install matplotlib)")
else:
    h = out.heights
    fig, ax = plt.subplots()
    ax.errorbar(h.pressure_pa, 1e3 * h.height_m, yerr=1.96e3 * h.height_std_m, fmt="o", label="measured (95 %)")
    for model, s in out.simulated.groupby("model"):
        ax.plot(s.pressure_pa, 1e3 * s.height_m, label=model)
    ax.set_xlabel("pressure (Pa)")
    ax.set_ylabel("apex height (mm)")
    ax.legend()
    fig.savefig("demo_heights.png", dpi=120)
    print("wrote demo_heights.png")
