"""Ground truth per camera pixel, for every renderer of :mod:`bistair.sim`.

Examples
--------
>>> import numpy as np
>>> t = Truth(coord_x=np.full((2, 2), 3.0), coord_y=np.zeros((2, 2)),
...           object_id=np.ones((2, 2), np.int32), mask=np.ones((2, 2), bool))
>>> t.coord("columns").tolist(), t.depth is None
([[3.0, 3.0], [3.0, 3.0]], True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..spec import BaseSpec


@dataclass(frozen=True, eq=False)
class Truth:
    """Ground truth per camera pixel (from the ray through the pixel centre).

    Attributes
    ----------
    coord_x, coord_y : continuous projector column and row (NaN where nothing is hit).
    object_id : surface object id, 0 for nothing.
    mask : ground truth usable for scoring: lit, not grazing, every sub-ray of the pixel on
        the same surface and lit, eroded by the edge margin.
    depth : z in the camera frame, mm (NaN where nothing is hit; ``None`` from renderers
        without 3-D geometry, like :mod:`~bistair.sim.warp`).
    points, normals : (H, W, 3) world point and unit normal facing the camera (NaN).
    lit : the point faces the projector, lies inside its image and not in its shadow.
    """

    coord_x: np.ndarray
    coord_y: np.ndarray
    object_id: np.ndarray
    mask: np.ndarray
    depth: np.ndarray | None = None
    points: np.ndarray | None = None
    normals: np.ndarray | None = None
    lit: np.ndarray | None = None

    def coord(self, spec: BaseSpec | str) -> np.ndarray:
        """The projector coordinate along a spec's coded axis (or ``"columns"``/``"rows"``)."""
        orientation = spec if isinstance(spec, str) else spec.orientation
        if orientation not in ("columns", "rows"):
            raise ValueError(f"orientation must be 'columns' or 'rows', got {orientation!r}")
        return self.coord_x if orientation == "columns" else self.coord_y
