"""From projector coordinates to 3-D: calibration boards, the calibration of a camera and a
projector, triangulation and the reference-plane height model."""
