"""
Calibrating a camera and a projector from board poses
=====================================================

The virtual rig renders a printed chessboard in six poses under the bidirectional code of
both projector axes with a white frame, as a lab would capture it;
:func:`~bistair.app.calibrate.calibrate_folder` finds the board in each pose, maps its
corners into the projector with a local homography of the decoded coordinates (Moreno and
Taubin) and calibrates both devices (Zhang and Huang), as ``bistair calibrate POSES --board
chessboard:9x6:20`` does. Against the rig's own parameters:
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import bistair
from bistair.app.calibrate import calibrate_folder
from bistair.geometry.board import Board
from bistair.geometry.calibration import Calibration
from bistair.sim import Imaging, Rig
from bistair.sim.boards import POSES, write_board_captures

rig = Rig.default(camera_size=(640, 512), projector_size=(800, 600))
board = Board("checkerboard", 9, 6, 20.0)
spec = bistair.make_spec("bidirectional", width=800, height=600, period=30, partitions=6,
                         stairs=6, white=1, orientation="both")
with tempfile.TemporaryDirectory() as tmp:
    folder = write_board_captures(rig, board, {"both": spec}, Path(tmp) / "calib",
                                  poses=POSES[:6], imaging=Imaging(read_noise=0.005, seed=1))
    cal = calibrate_folder(folder, board=board,
                           skipped=lambda name, why: print(f"skipped {name}: {why}"))

truth = Calibration.from_rig(rig)
print(f"reprojection RMS {cal.rms:.3f} px")
for name, got, want in (("camera fx", cal.camera.K[0, 0], truth.camera.K[0, 0]),
                        ("projector fx", cal.projector.K[0, 0], truth.projector.K[0, 0]),
                        ("baseline |T|", cal.baseline, truth.baseline)):
    print(f"{name:13s} {got:9.2f}  (rig {want:9.2f}: {100 * (got / want - 1):+.2f}%)")

# %%
# The errors against the rig.
fig, ax = plt.subplots(figsize=(6, 3), layout="constrained")
labels = ["camera fx", "projector fx", "baseline"]
errors = [100 * (cal.camera.K[0, 0] / truth.camera.K[0, 0] - 1),
          100 * (cal.projector.K[0, 0] / truth.projector.K[0, 0] - 1),
          100 * (cal.baseline / truth.baseline - 1)]
ax.bar(labels, errors, color=["tab:blue", "tab:orange", "tab:green"])
ax.axhline(0, color="k", lw=0.5)
ax.set_ylabel("error against the rig (%)")
plt.show()
