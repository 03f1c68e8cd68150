"""The virtual projector-camera rig (bistair.sim) against closed-form geometry and OpenCV.

Measured tolerance of the end-to-end decode: on the ``plane`` preset (640 x 512 camera,
1080 x 1080 projector, 2 x 2 supersampling, nearest projector pixels, default noise) the
bidirectional decoder covers every truth pixel with no order error; its coordinate error is
0.115 projector pixels RMS (0.024 rad), 0.30 px at the 99th percentile and 0.83 px at most
(seeds 3 and 4). Asserted: RMS < 0.15 px, 99th percentile < 0.4 px, maximum < 1.2 px.
"""

import cv2
import numpy as np
import pytest
import trimesh

import bistair
from bistair.evaluation.metrics import score
from bistair.sim import (
    Box,
    Camera,
    Ellipsoid,
    Imaging,
    MaskRelief,
    Mesh,
    Plane,
    Prism,
    Rig,
    Scene,
    Sphere,
    expose,
    preset,
    preset_spec,
    render,
    scene_names,
    trace,
)

QUIET = dict(read_noise=0.0, full_well=0.0, bits=None, camera_blur=0.0, projector_blur=0.0,
             projector_bits=None)
DIST = (-0.12, 0.08, 1e-3, -6e-4, -0.02)


def small_rig(**kw):
    return Rig.default(**{"camera_size": (320, 256), "projector_size": (1080, 1080), **kw})


# -- geometry against closed forms -------------------------------------------------------------

@pytest.mark.parametrize("roll", [0.0, 2.0])
def test_plane_coordinates_match_the_pinhole_closed_form(roll):
    depth, base = 600.0, 200.0
    rig = small_rig(roll_deg=roll, baseline=base, working_distance=600)
    truth = trace(rig, Scene([Plane(center=(0, 0, depth))]), Imaging(supersample=1)).truth
    cam, proj = rig.camera, rig.projector
    v, u = np.mgrid[0:256:17, 0:320:13].astype(float)
    x, y = (u - cam.cx) / cam.fx * depth, (v - cam.cy) / cam.fy * depth
    th, r = np.arctan2(base, 600.0), np.deg2rad(roll)
    xp = (x - base) * np.cos(th) + depth * np.sin(th)  # yawed toward the scene centre
    zp = -(x - base) * np.sin(th) + depth * np.cos(th)
    xr, yr = np.cos(r) * xp + np.sin(r) * y, -np.sin(r) * xp + np.cos(r) * y  # rolled
    col, row = proj.cx + proj.fx * xr / zp, proj.cy + proj.fy * yr / zp
    iv, iu = v.astype(int), u.astype(int)
    assert np.abs(truth.coord_x[iv, iu] - col).max() < 1e-6
    assert np.abs(truth.coord_y[iv, iu] - row).max() < 1e-6
    assert np.abs(truth.depth - depth).max() < 1e-9
    assert np.allclose(truth.points[..., 2], depth) and truth.mask.all()


def test_sphere_silhouette_is_where_geometry_puts_it():
    radius, dist = 40.0, 500.0
    rig = small_rig()
    truth = trace(rig, Scene([Sphere(center=(0, 0, dist), radius=radius)]),
                  Imaging(supersample=1)).truth
    cam = rig.camera
    r_img = cam.fx * radius / np.sqrt(dist**2 - radius**2)
    v, u = np.mgrid[0:256, 0:320]
    rho = np.hypot(u - cam.cx, v - cam.cy)
    clear = np.abs(rho - r_img) > 1e-3
    assert np.array_equal((truth.object_id == 1)[clear], (rho < r_img)[clear])
    hit = truth.object_id == 1
    assert np.abs(np.linalg.norm(truth.points[hit] - (0, 0, dist), axis=1) - radius).max() < 1e-9


def _segment_hits_sphere(points, target, centre, radius):
    d = target - points
    w = points - centre
    a, b, c = (d * d).sum(1), (d * w).sum(1), (w * w).sum(1) - radius**2
    disc = b * b - a * c
    root = np.sqrt(np.maximum(disc, 0))
    t1, t2 = (-b - root) / a, (-b + root) / a
    return (disc > 0) & (((t1 > 1e-9) & (t1 < 1)) | ((t2 > 1e-9) & (t2 < 1)))


def test_projector_shadow_on_the_background_is_where_geometry_puts_it():
    rig, scene = preset("sphere-on-plane", camera_size=(320, 256))
    truth = trace(rig, scene, Imaging(supersample=1)).truth
    sphere = scene.surfaces[0]
    plane = truth.object_id == 2
    pts = truth.points[plane]
    shadowed = _segment_hits_sphere(pts, rig.projector.center, sphere.center, sphere.radius)
    assert 2000 < shadowed.sum() < plane.sum() // 2
    assert np.array_equal(truth.lit[plane], ~shadowed)
    # the shadow falls away from the projector (which is at +x): left of the sphere
    assert truth.points[plane][shadowed][:, 0].max() < 0
    # camera occlusion: the plane is hidden behind the sphere, depth steps at the silhouette
    assert (truth.object_id == 1).sum() > 1000
    assert np.nanmax(truth.depth[truth.object_id == 1]) < 520


@pytest.mark.parametrize("dist", [(0.0,) * 5, DIST])
def test_projection_agrees_with_opencv(dist):
    rig = Rig.default(camera_dist=dist, projector_dist=dist, roll_deg=2.0)
    rng = np.random.default_rng(5)
    pts = np.column_stack([rng.uniform(-150, 150, 200), rng.uniform(-120, 120, 200),
                           rng.uniform(450, 800, 200)])
    for dev in (rig.camera, rig.projector):
        ref, _ = cv2.projectPoints(pts, dev.rvec, dev.t, dev.K, dev.dist_coeffs)
        assert np.abs(dev.project(pts) - ref[:, 0]).max() < 1e-6
    # rays and projection invert each other (distortion is inverted to machine precision)
    cam = rig.camera
    u, v = rng.uniform(0, 1279, 500), rng.uniform(0, 1023, 500)
    back = cam.project(cam.center + 600 * cam.rays(u, v))
    assert np.abs(back - np.column_stack([u, v])).max() < 1e-6


def test_truth_with_distortion_agrees_with_opencv():
    rig = small_rig(camera_dist=DIST, projector_dist=DIST, camera_focal=600)
    truth = trace(rig, Scene([Plane(center=(0, 0, 620)), Sphere(center=(20, 0, 560),
                                                              radius=30)]),
                  Imaging(supersample=1)).truth
    hit = truth.object_id > 0
    proj = rig.projector
    ref, _ = cv2.projectPoints(truth.points[hit], proj.rvec, proj.t, proj.K, proj.dist_coeffs)
    assert np.abs(ref[:, 0, 0] - truth.coord_x[hit]).max() < 1e-6
    assert np.abs(ref[:, 0, 1] - truth.coord_y[hit]).max() < 1e-6
    cam = rig.camera
    ref, _ = cv2.projectPoints(truth.points[hit], cam.rvec, cam.t, cam.K, cam.dist_coeffs)
    v, u = np.nonzero(hit)
    assert np.abs(ref[:, 0] - np.column_stack([u, v])).max() < 1e-6


def test_shapes_meshes_and_files_intersect_consistently(tmp_path):
    rig = small_rig(camera_focal=600)
    sphere = Sphere(center=(0, 0, 500), radius=40)
    ico = trimesh.creation.icosphere(subdivisions=5, radius=40)
    path = tmp_path / "ball.ply"
    ico.export(path)
    depths = []
    for surface in (sphere, Ellipsoid(center=(0, 0, 500), radii=(40, 40, 40),
                                      rotation=cv2.Rodrigues(np.array([0.3, 0.2, 0.1]))[0]),
                    Mesh(mesh=ico, center=(0, 0, 500)), Mesh(mesh=str(path), center=(0, 0, 500))):
        truth = trace(rig, Scene([surface]), Imaging(supersample=1)).truth
        depths.append(truth.depth[128, 160])
        assert np.allclose(np.linalg.norm(truth.normals[128, 160]), 1.0)
    d = rig.camera.rays(160.0, 128.0)  # camera-frame z = 1: t is the depth
    b, c = d @ (0, 0, 500.0), 500.0**2 - 40.0**2
    expected = (b - np.sqrt(b * b - (d @ d) * c)) / (d @ d)
    assert abs(depths[0] - expected) < 1e-9 and abs(depths[1] - expected) < 1e-9
    assert abs(depths[2] - expected) < 0.05 and abs(depths[3] - depths[2]) < 1e-4  # float32 file
    box = Box(center=(0, 0, 500), size=(60, 40, 20))
    assert trace(rig, Scene([box]), Imaging(supersample=1)).truth.depth[128, 160] == 490.0
    prism = Prism(center=(0, 0, 500), width=40, depth=20, length=50)
    truth = trace(rig, Scene([prism]), Imaging(supersample=1)).truth
    x = truth.points[128, 160, 0]  # the ridge faces the camera; its faces slope 20/20
    assert 0 < x < 1 and abs(truth.depth[128, 160] - (480.0 + abs(x))) < 1e-9


# -- image formation ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def sphere_scene():
    rig, scene = preset("sphere-on-plane", camera_size=(320, 256))
    return rig, scene, trace(rig, scene, Imaging(camera_blur=1.0))


@pytest.fixture(scope="module")
def plane_trace():
    rig, scene = preset("plane", camera_size=(160, 128), projector_size=(1080, 1080))
    return trace(rig, scene, Imaging())


def test_same_seed_same_images_other_seed_other_noise(sphere_scene):
    rig, scene, traced = sphere_scene
    pats = bistair.encode(preset_spec("sphere-on-plane"))
    a, truth_a = render(pats, rig, scene, Imaging(seed=7))
    b, truth_b = render(pats, rig, scene, Imaging(seed=7))
    c = expose(traced, pats, Imaging(seed=8))
    assert np.array_equal(a, b) and np.array_equal(truth_a.coord_x, truth_b.coord_x, True)
    assert not np.array_equal(a, c) and np.abs(a.astype(int) - c).mean() < 3


def test_result_does_not_depend_on_threads():
    rig, scene = preset("paper-sim", camera_size=(320, 256))
    one, many = trace(rig, scene, workers=1), trace(rig, scene, workers=3)
    pats = bistair.encode(preset_spec("paper-sim"))
    assert np.array_equal(one.truth.mask, many.truth.mask)
    assert np.array_equal(one.truth.coord_x, many.truth.coord_x, equal_nan=True)
    assert np.array_equal(expose(one, pats, workers=1), expose(many, pats, workers=3))


def test_gamma_linear_uncompensated_and_compensated(plane_trace):
    flat = np.full((1, 1080, 1080), 0.5, np.float32)
    quiet = dict(QUIET, ambient=0.0)
    lin = expose(plane_trace, flat, Imaging(gamma=1.0, **quiet))
    unc = expose(plane_trace, flat, Imaging(gamma=2.2, **quiet))
    lit = plane_trace.truth.mask
    assert np.allclose(unc[0][lit] / lin[0][lit], 0.5**1.2, rtol=1e-5)
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
    linear = expose(plane_trace, bistair.encode(spec), Imaging(gamma=1.0, **quiet))
    compensated = expose(plane_trace, bistair.encode(spec.replace(gamma=2.2)),
                         Imaging(gamma=2.2, **quiet))
    uncompensated = expose(plane_trace, bistair.encode(spec), Imaging(gamma=2.2, **quiet))
    assert np.abs(compensated - linear).max() < 1e-5
    assert np.abs(uncompensated - linear).max() > 0.1


def test_saturation_quantisation_and_ambient(plane_trace):
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
    pats = bistair.encode(spec)
    hot = expose(plane_trace, pats, Imaging(exposure=4.0))
    assert hot.dtype == np.uint8 and hot.max() == 255 and (hot == 255).mean() > 0.3
    for bits in (10, 12, 16):
        img = expose(plane_trace, pats, Imaging(bits=bits))
        assert img.dtype == np.uint16 and img.max() <= (1 << bits) - 1
        assert img.max() > 0.5 * (1 << bits)
    fl = expose(plane_trace, pats, Imaging(float_output=True))
    assert fl.dtype == np.float32 and np.allclose(fl * 255, np.round(fl * 255), atol=1e-4)
    raw = expose(plane_trace, pats, Imaging(bits=None))
    assert raw.dtype == np.float32 and not np.allclose(raw * 255, np.round(raw * 255))
    dark = np.zeros_like(pats[:1])
    assert expose(plane_trace, dark, Imaging(ambient=0.0, **QUIET)).max() == 0.0
    amb = expose(plane_trace, dark, Imaging(ambient=0.1, exposure=0.8, **QUIET))
    assert np.allclose(amb, 0.1 * 0.8 * 0.8)  # ambient * exposure * albedo of the plane


def test_albedo_texture_modulates_the_image():
    rig = small_rig(camera_size=(160, 128))
    stripes = Plane(center=(0, 0, 600), albedo=lambda p: np.where(p[:, 0] > 0, 0.8, 0.2))
    traced = trace(rig, Scene([stripes]), Imaging(supersample=1, edge_margin=0))
    img = expose(traced, np.zeros((1, 1080, 1080)), Imaging(ambient=0.5, **QUIET))[0]
    x = traced.truth.points[..., 0]
    assert np.allclose(img[x > 1], 0.5 * 0.8 * 0.8) and np.allclose(img[x < -1], 0.5 * 0.8 * 0.2)
    lit = expose(traced, np.ones((1, 1080, 1080)), Imaging(ambient=0.0, **QUIET))[0]
    assert lit[x > 1].mean() > 3 * lit[x < -1].mean()


def test_mask_excludes_silhouettes_and_shadow_edges(sphere_scene):
    _, _, traced = sphere_scene
    truth = traced.truth
    assert 0.5 < truth.mask.mean() < 0.95 and not (truth.mask & ~truth.lit).any()

    def edges(field):
        f = np.pad(field, 1, mode="edge")
        return ((f[1:-1, 1:-1] != f[:-2, 1:-1]) | (f[1:-1, 1:-1] != f[2:, 1:-1])
                | (f[1:-1, 1:-1] != f[1:-1, :-2]) | (f[1:-1, 1:-1] != f[1:-1, 2:]))

    silhouette, shadow_edge = edges(truth.object_id), edges(truth.lit)
    assert silhouette.sum() > 100 and shadow_edge.sum() > 100
    assert not (truth.mask & (silhouette | shadow_edge)).any()
    assert truth.mask[truth.object_id == 1].mean() > 0.5  # sphere mostly ground truth


def test_truth_coord_follows_the_spec_orientation():
    rig, scene = preset("plane", camera_size=(480, 384), projector_size=(1080, 1080))
    cols = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
    rows = cols.replace(orientation="rows")
    images, truth = render(bistair.encode(rows), rig, scene, Imaging(seed=2))
    assert truth.coord(cols) is truth.coord_x and truth.coord(rows) is truth.coord_y
    m = score(bistair.decode(images, rows), truth.coord(rows), truth.mask)
    assert m["order_errors"] == 0 and m["coverage"] > 0.99


# -- end to end --------------------------------------------------------------------------------

def test_bidirectional_decodes_the_rendered_plane():
    rig, scene = preset("plane", camera_size=(640, 512), projector_size=(1080, 1080))
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
    images, truth = render(bistair.encode(spec), rig, scene, Imaging(seed=3))
    result = bistair.decode(images, spec)
    m = score(result, truth.coord(spec), truth.mask)
    assert m["order_errors"] == 0 and m["coverage"] > 0.999
    both = result.mask & truth.mask
    err = result.coord[both] - truth.coord(spec)[both]
    assert np.sqrt(np.mean(err**2)) < 0.15 and np.percentile(np.abs(err), 99) < 0.4
    assert np.abs(err).max() < 1.2
    phase_err = result.phase[both] - 2 * np.pi * truth.coord(spec)[both] / spec.period
    assert (np.abs(phase_err) > np.pi).sum() == 0


# -- presets -----------------------------------------------------------------------------------

def _spans(truth, object_id):
    sel = truth.mask & (truth.object_id == object_id)
    return np.ptp(truth.coord_x[sel]), np.ptp(truth.coord_y[sel])


def test_presets_exist_and_take_overrides():
    assert scene_names() == ["plane", "sphere-on-plane", "paper-sim", "two-masks", "mask-prism",
                             "two-sculptures", "objects-on-plane", "mugs-on-wall"]
    rig, _ = preset("paper-sim", camera_size=(640, 512), roll_deg=2)
    assert rig.camera.size == (640, 512) and rig.projector.size == (1080, 1080)
    assert isinstance(rig.camera, Camera)
    with pytest.raises(ValueError, match="unknown preset"):
        preset("nope")


@pytest.mark.parametrize(("field", "value", "message"), [
    ("gamma", 0.0, "projector gamma (gamma) must be a finite number above 0, got 0.0"),
    ("ambient", float("nan"), "ambient light (ambient) must be a finite number of at least 0"),
    ("exposure", -1.0, "exposure (exposure) must be a finite number above 0"),
    ("read_noise", -0.01, "read noise (read_noise) must be a finite number of at least 0"),
    ("full_well", float("inf"), "full well (full_well) must be a finite number of at least 0"),
    ("camera_blur", "1", "camera blur (camera_blur) must be a finite number of at least 0"),
    ("projector_blur", -0.5, "projector blur (projector_blur) must be a finite number"),
    ("max_incidence_deg", 95.0, "incidence limit (max_incidence_deg) must be at most 90"),
    ("max_incidence_deg", 0.0, "incidence limit (max_incidence_deg) must be a finite number "
                               "above 0"),
    ("bits", 9, "camera bits (bits) must be 8, 10, 12, 14, 16 or None, got 9"),
    ("bits", 8.0, "camera bits (bits) must be 8, 10, 12, 14, 16 or None, got 8.0"),
    ("projector_bits", 0, "projector bits (projector_bits) must be a whole number from 1 to 16 "
                          "or None, got 0"),
    ("projector_sampling", "cubic", "projector_sampling must be 'nearest' or 'linear'"),
    ("supersample", 0, "sub-rays per pixel side (supersample) must be a whole number from 1 to "
                       "16, got 0"),
    ("edge_margin", -1, "edge margin (edge_margin) must be a whole number of at least 0 or None"),
    ("seed", -1, "seed must be a whole number of at least 0, got -1"),
    ("float_output", 1, "float_output must be True or False, got 1"),
    ("inverse_square", None, "inverse_square must be True or False, got None"),
])
def test_imaging_refuses_each_bad_field(field, value, message):
    with pytest.raises(bistair.BistairError) as exc:
        Imaging(**{field: value})
    assert str(exc.value) == message or str(exc.value).startswith(message)
    Imaging(**{field: Imaging.__dataclass_fields__[field].default})  # the default is fine


@pytest.mark.parametrize("size", [(0, 0), (-5, 10), (7, 100), (640, 9000), (640.0, 480), (1,)])
def test_simulated_devices_have_sensible_sizes(size):
    with pytest.raises(bistair.BistairError, match="camera size"):
        Rig.default(camera_size=size)
    with pytest.raises(bistair.BistairError, match="projector size"):
        Rig.default(projector_size=size)


def test_paper_sim_has_a_big_object_and_small_ones_one_to_three_fringes_wide():
    rig, scene = preset("paper-sim", camera_size=(640, 512))
    truth = trace(rig, scene, Imaging()).truth
    assert isinstance(scene.surfaces[0], MaskRelief) and scene.ids == (1, 2, 3, 4)
    assert (truth.object_id == 1).mean() > 0.4
    for i in (2, 3, 4):
        width, height = _spans(truth, i)
        assert 30 <= width <= 90 and height >= 45, (i, width, height)
    assert 0 < (truth.object_id > 1).mean() < 0.03


def test_mask_prism_prism_carries_two_to_four_fringes():
    rig, scene = preset("mask-prism", camera_size=(320, 256))
    truth = trace(rig, scene, Imaging()).truth
    width, _ = _spans(truth, 2)
    assert 60 <= width <= 120
