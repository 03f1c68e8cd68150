"""
Fringe orders under camera noise
================================

Order errors and coverage of the bidirectional code, the Gray code and Lv's code as the
camera's read noise grows, on the paper's scene of the virtual rig (one seed each; the
benchmark ``benchmarks/robustness.py --sweeps`` takes the median of three). A refused
decode is drawn as refused, not as a decode without errors.
"""

import matplotlib.pyplot as plt

from bistair.evaluation.benchmark import method_specs, run
from bistair.sim import Imaging, preset, trace

rig, scene = preset("paper-sim", camera_size=(320, 256))
specs = method_specs(rig.projector.size, period=30, gamma=2.2,
                     methods=["bidirectional", "graycode", "lv"])
noises = [0.005, 0.02, 0.04, 0.08]
table = {label: [] for label in specs}
for noise in noises:
    imaging = Imaging(gamma=2.2, read_noise=noise, camera_blur=1.0, seed=0)
    comparison = run(trace(rig, scene, imaging), specs)
    for row in comparison.rows:
        refused = "refused" in row.result.info
        table[row.label].append(None if refused else (row.scores["order_error_rate"],
                                                      row.scores["coverage"]))

fig, axes = plt.subplots(1, 2, figsize=(11, 3.6), layout="constrained")
for label, values in table.items():
    shown = [(n, v) for n, v in zip(noises, values, strict=True) if v is not None]
    line, = axes[0].plot([n for n, _ in shown], [100 * v[0] for _, v in shown], "o-",
                         label=label)
    axes[1].plot([n for n, _ in shown], [100 * v[1] for _, v in shown], "o-",
                 color=line.get_color())
    for n, v in zip(noises, values, strict=True):
        if v is None:
            axes[1].annotate("refused", (n, 0), color=line.get_color(), ha="center")
axes[0].set_xlabel("read noise (fraction of full scale)")
axes[0].set_ylabel("orders wrong (% of decoded)")
axes[1].set_xlabel("read noise (fraction of full scale)")
axes[1].set_ylabel("coverage (% of the truth)")
axes[0].legend()
plt.show()
