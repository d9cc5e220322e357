"""The demo experiment from Python: bulge.run on data/demo, then the measured
heights with their 95 % band (1.96 x height_std_m) and each model's simulated
heights. Run from the repository root: python python/examples/demo.py
(matplotlib optional: without it the tables are printed only)."""

import pathlib

import bulge

root = pathlib.Path(__file__).resolve().parents[2]
out = bulge.run(root / "data/demo/experiment.toml")
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
