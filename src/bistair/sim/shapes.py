"""Surfaces the rig sees, and the scene that ray-casts them.

Every surface answers one question, vectorised over a bundle of rays from one point:
:meth:`Surface.intersect` gives the nearest hit ``t > tmin`` of ``origin + t * dirs`` (``inf``
where missed) and, on request, the unit surface normal there. Each surface carries an object
id and an albedo (a constant or a function of the 3-D points). Units are millimetres, in the
camera frame (x right, y down, z away from the camera).

Examples
--------
>>> import numpy as np
>>> scene = Scene([Sphere(center=(0, 0, 500), radius=50),
...                Plane(center=(0, 0, 800), albedo=0.5)])
>>> dirs = np.array([[0.0, 0.0, 1.0], [0.3, 0.0, 1.0]])
>>> t, which, normals = scene.cast(np.zeros(3), dirs)
>>> t.round(3).tolist(), which.tolist(), scene.ids
([450.0, 800.0], [0, 1], (1, 2))
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import ArrayLike

from .raycast import Triangles, barycentric
from .rig import apply, dot

Albedo = float | Callable[[np.ndarray], np.ndarray]


def _vec(value: ArrayLike) -> np.ndarray:
    return np.asarray(value, float).reshape(3)


def _rot(value: ArrayLike | None) -> np.ndarray:
    return np.eye(3) if value is None else np.asarray(value, float).reshape(3, 3)


def _unit(v: np.ndarray) -> np.ndarray:
    if v.ndim == 1:
        return v / np.sqrt(v @ v)
    return v / np.sqrt(dot(v, v))[:, None]


@dataclass(frozen=True, eq=False, kw_only=True)
class Surface:
    """Base class: object id (``None``: numbered by the scene) and albedo.

    A new kind of surface implements :meth:`intersect` and, to be skipped quickly by rays
    that miss it, :meth:`bound`.
    """

    object_id: int | None = None
    albedo: Albedo = 1.0

    def albedo_at(self, points: np.ndarray) -> np.ndarray:
        """Albedo at world points ``(N, 3)``."""
        if callable(self.albedo):
            return np.asarray(self.albedo(points), float).reshape(len(points))
        return np.full(len(points), float(self.albedo))

    def bound(self) -> tuple[np.ndarray, float]:
        """A bounding sphere ``(centre, radius)`` (radius ``inf``: unbounded)."""
        return np.zeros(3), np.inf

    def intersect(self, origin: np.ndarray, dirs: np.ndarray, tmin: float = 0.0,
                  normals: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Nearest ``t > tmin`` per ray (``inf`` if none) and unit normals (NaN if none)."""
        raise NotImplementedError


def _quadric_roots(a, b, c):
    """Sorted real roots of ``a t^2 + 2 b t + c`` (NaN where none), stable form."""
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(disc)
        q = -(b + np.copysign(root, b))
        t1, t2 = q / a, c / q
    lo, hi = np.minimum(t1, t2), np.maximum(t1, t2)
    return np.where(disc >= 0, lo, np.nan), np.where(disc >= 0, hi, np.nan)


def _nearest(lo, hi, tmin):
    t = np.where(lo > tmin, lo, np.where(hi > tmin, hi, np.inf))
    return np.where(np.isnan(t), np.inf, t)


@dataclass(frozen=True, eq=False, kw_only=True)
class Ellipsoid(Surface):
    """An ellipsoid: centre, semi-axes (along its local axes) and rotation (local to world)."""

    center: ArrayLike = (0.0, 0.0, 600.0)
    radii: ArrayLike = (50.0, 50.0, 50.0)
    rotation: ArrayLike | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _vec(self.center))
        object.__setattr__(self, "radii", _vec(self.radii))
        object.__setattr__(self, "rotation", _rot(self.rotation))

    def bound(self):
        return self.center, float(self.radii.max())

    def _local(self, origin, dirs):
        o = (self.rotation.T @ (origin - self.center)) / self.radii
        return o, apply(self.rotation.T, dirs) / self.radii

    def intersect(self, origin, dirs, tmin=0.0, normals=True):
        o, d = self._local(origin, dirs)
        t = _nearest(*_quadric_roots(dot(d, d), dot(d, o), o @ o - 1.0), tmin)
        if not normals:
            return t, None
        p = o + np.where(np.isfinite(t), t, np.nan)[:, None] * d  # on the unit sphere
        return t, _unit(apply(self.rotation, p / self.radii))


@dataclass(frozen=True, eq=False, kw_only=True)
class Sphere(Surface):
    """A sphere of ``radius`` around ``center``."""

    center: ArrayLike = (0.0, 0.0, 600.0)
    radius: float = 50.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _vec(self.center))

    def bound(self):
        return self.center, float(self.radius)

    def intersect(self, origin, dirs, tmin=0.0, normals=True):
        o = origin - self.center
        t = _nearest(*_quadric_roots(dot(dirs, dirs), dot(dirs, o), o @ o - self.radius**2),
                     tmin)
        if not normals:
            return t, None
        return t, (o + np.where(np.isfinite(t), t, np.nan)[:, None] * dirs) / self.radius


@dataclass(frozen=True, eq=False, kw_only=True)
class _Convex(Surface):
    """A convex polyhedron: half-spaces ``n . x <= d`` in its local frame."""

    center: ArrayLike = (0.0, 0.0, 600.0)
    rotation: ArrayLike | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _vec(self.center))
        object.__setattr__(self, "rotation", _rot(self.rotation))
        n, d, r = self._halfspaces()
        object.__setattr__(self, "_n", n)
        object.__setattr__(self, "_d", d)
        object.__setattr__(self, "_r", r)

    def _halfspaces(self) -> tuple[np.ndarray, np.ndarray, float]:
        raise NotImplementedError

    def bound(self):
        return self.center, self._r

    def intersect(self, origin, dirs, tmin=0.0, normals=True):
        o = self.rotation.T @ (origin - self.center)
        d = apply(self.rotation.T, dirs)
        num = self._d - self._n @ o  # (K,)
        den = apply(self._n, d)  # (N, K)
        with np.errstate(divide="ignore", invalid="ignore"):
            ts = num / den
        enter = np.where(den < 0, ts, -np.inf)
        leave = np.where(den > 0, ts, np.inf)
        k_in, k_out = enter.argmax(axis=1), leave.argmin(axis=1)
        rows = np.arange(len(d))
        t_in, t_out = enter[rows, k_in], leave[rows, k_out]
        blocked = ((den == 0) & (num < 0)).any(axis=1)
        hit = ~blocked & (t_in <= t_out)
        use_in = t_in > tmin
        t = np.where(hit & use_in, t_in, np.where(hit & (t_out > tmin), t_out, np.inf))
        if not normals:
            return t, None
        n = apply(self.rotation, self._n[np.where(use_in, k_in, k_out)])
        return t, np.where(np.isfinite(t)[:, None], n, np.nan)


@dataclass(frozen=True, eq=False, kw_only=True)
class Box(_Convex):
    """A box: centre, edge lengths ``size`` along its local axes, rotation (local to world)."""

    size: ArrayLike = (50.0, 50.0, 50.0)

    def _halfspaces(self):
        half = _vec(self.size) / 2
        n = np.vstack([np.eye(3), -np.eye(3)])
        return n, np.concatenate([half, half]), float(np.linalg.norm(half))


@dataclass(frozen=True, eq=False, kw_only=True)
class Prism(_Convex):
    """A triangular prism with its ridge toward the camera.

    Local frame: the cross-section lies in x-z, a triangle with its base (``width`` wide) at
    ``z = 0`` and its apex ``depth`` toward the camera (``z = -depth``); it is extruded over
    ``length`` along y. ``center`` is the middle of the base face.
    """

    width: float = 30.0
    depth: float = 15.0
    length: float = 60.0

    def _halfspaces(self):
        w2, h, l2 = self.width / 2, self.depth, self.length / 2
        side = np.hypot(h, w2)
        n = np.array([[0, 0, 1.0], [0, 1.0, 0], [0, -1.0, 0],
                      [-h / side, 0, -w2 / side], [h / side, 0, -w2 / side]])
        d = np.array([0.0, l2, l2, h * w2 / side, h * w2 / side])
        return n, d, float(np.sqrt(max(w2, h) ** 2 + l2**2))


@dataclass(frozen=True, eq=False, kw_only=True)
class Plane(Surface):
    """A plane through ``center`` with ``normal``; a ``size = (w, h)`` rectangle or unbounded.

    The rectangle's first side runs along ``x_axis`` (made orthogonal to the normal).
    """

    center: ArrayLike = (0.0, 0.0, 600.0)
    normal: ArrayLike = (0.0, 0.0, -1.0)
    size: tuple[float, float] | None = None
    x_axis: ArrayLike = (1.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        n = _unit(_vec(self.normal))
        x = _vec(self.x_axis)
        x = _unit(x - (x @ n) * n)
        object.__setattr__(self, "center", _vec(self.center))
        object.__setattr__(self, "normal", n)
        object.__setattr__(self, "x_axis", x)

    def bound(self):
        if self.size is None:
            return self.center, np.inf
        return self.center, float(np.hypot(*self.size) / 2)

    def intersect(self, origin, dirs, tmin=0.0, normals=True):
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (self.normal @ (self.center - origin)) / dot(dirs, self.normal)
        t = np.where(t > tmin, t, np.inf)
        if self.size is not None:
            tt = np.where(np.isfinite(t), t, 0.0)
            o = origin - self.center
            y_axis = np.cross(self.normal, self.x_axis)
            inside = ((np.abs(o @ self.x_axis + tt * dot(dirs, self.x_axis)) <= self.size[0] / 2)
                      & (np.abs(o @ y_axis + tt * dot(dirs, y_axis)) <= self.size[1] / 2))
            t = np.where(inside, t, np.inf)
        if not normals:
            return t, None
        return t, np.where(np.isfinite(t)[:, None], self.normal, np.nan)


@dataclass(frozen=True, eq=False, kw_only=True)
class _Triangles(Surface):
    """Shared machinery of triangle surfaces (after ``_set_mesh``)."""

    smooth: bool = True

    def _set_mesh(self, vertices: np.ndarray, faces: np.ndarray,
                  vertex_normals: np.ndarray | None) -> None:
        tris = vertices[faces]
        centre = (vertices.min(axis=0) + vertices.max(axis=0)) / 2
        object.__setattr__(self, "_tris", tris)
        object.__setattr__(self, "_set", Triangles(tris))
        object.__setattr__(self, "_faces", faces)
        object.__setattr__(self, "_face_normals", _unit(np.cross(tris[:, 1] - tris[:, 0],
                                                                 tris[:, 2] - tris[:, 0])))
        object.__setattr__(self, "_vertex_normals", vertex_normals)
        object.__setattr__(self, "_bound", (centre, float(
            np.linalg.norm(vertices - centre, axis=1).max())))

    def bound(self):
        return self._bound

    @property
    def triangles(self) -> np.ndarray:
        """The world-space triangles ``(M, 3, 3)``."""
        return self._tris

    def intersect(self, origin, dirs, tmin=0.0, normals=True):
        t, face = self._set.intersect(origin, dirs, tmin)
        if not normals:
            return t, None
        hit = face >= 0
        n = np.full(dirs.shape, np.nan)
        if self.smooth and self._vertex_normals is not None:
            f = face[hit]
            u, v = barycentric(self._tris[f], origin + t[hit, None] * dirs[hit])
            n0, n1, n2 = (self._vertex_normals[self._faces[f, k]] for k in range(3))
            n[hit] = _unit(n0 + u[:, None] * (n1 - n0) + v[:, None] * (n2 - n0))
        else:
            n[hit] = self._face_normals[face[hit]]
        return t, n


@dataclass(frozen=True, eq=False, kw_only=True)
class Mesh(_Triangles):
    """A triangle mesh: a ``trimesh.Trimesh`` or a file ``trimesh`` can load.

    The mesh is scaled by ``scale``, rotated by ``rotation`` and moved to ``center``
    (``X = center + rotation @ (scale * x)``). With ``smooth`` (default) normals are
    interpolated from the vertex normals; otherwise each face is flat.
    """

    mesh: object = None
    center: ArrayLike = (0.0, 0.0, 0.0)
    rotation: ArrayLike | None = None
    scale: float = 1.0

    def __post_init__(self) -> None:
        mesh = self.mesh
        if isinstance(mesh, str | Path):
            mesh = trimesh.load(mesh, force="mesh")
        if not isinstance(mesh, trimesh.Trimesh):
            raise TypeError("Mesh needs a trimesh.Trimesh or a path to a mesh file")
        if self.smooth:
            mesh = mesh.smooth_shaded  # vertices split at sharp edges
        rot = _rot(self.rotation)
        verts = _vec(self.center) + (self.scale * np.asarray(mesh.vertices, float)) @ rot.T
        normals = np.asarray(mesh.vertex_normals, float) @ rot.T
        self._set_mesh(verts, np.asarray(mesh.faces, np.int64), normals)


@dataclass(frozen=True, eq=False, kw_only=True)
class MaskRelief(_Triangles):
    """A face-like mask: a relief over an ellipse, facing the camera.

    In its local frame (x right, y down, z away from the camera, like the camera's) the
    surface is ``z = -h(x, y)`` over the ellipse ``(x/a)^2 + (y/b)^2 <= 1``, ``a = width/2``,
    ``b = height/2``: a dome of ``depth`` falling to 0 at the rim (where it is seen edge-on),
    with smooth bumps for the forehead, nose, cheeks and chin and hollows for the eyes.
    ``center`` is the middle of the rim's plane; ``rotation`` turns the mask (local to
    world). It is tessellated on ``rings x sectors`` polar rings (a mesh, so the ground truth
    is that mesh's geometry).
    """

    center: ArrayLike = (0.0, 0.0, 600.0)
    width: float = 140.0
    height: float = 180.0
    depth: float = 50.0
    rotation: ArrayLike | None = None
    rings: int = 48
    sectors: int = 160

    def __post_init__(self) -> None:
        rho = np.sin(0.5 * np.pi * np.arange(1, self.rings + 1) / self.rings)
        ang = 2 * np.pi * np.arange(self.sectors) / self.sectors
        x = np.concatenate([[0.0], (rho[:, None] * np.cos(ang)).ravel()]) * self.width / 2
        y = np.concatenate([[0.0], (rho[:, None] * np.sin(ang)).ravel()]) * self.height / 2
        local = np.stack([x, y, -self.relief(x, y)], axis=1)
        s, r = self.sectors, self.rings
        ring = 1 + np.arange(r)[:, None] * s + np.arange(s)[None, :]  # vertex ids per ring
        nxt = np.roll(ring, -1, axis=1)
        fan = np.stack([np.zeros(s, np.int64), ring[0], nxt[0]], axis=1)
        quads = [np.stack([ring[:-1], ring[1:], nxt[1:]], -1), np.stack([ring[:-1], nxt[1:],
                                                                         nxt[:-1]], -1)]
        faces = np.concatenate([fan] + [q.reshape(-1, 3) for q in quads])
        mesh = trimesh.Trimesh(local, faces, process=False)
        rot = _rot(self.rotation)
        verts = _vec(self.center) + local @ rot.T
        self._set_mesh(verts, faces, np.asarray(mesh.vertex_normals, float) @ rot.T)

    def relief(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Height toward the camera at local ``(x, y)`` (0 outside the ellipse)."""
        a, b = self.width / 2, self.height / 2
        u, v = x / a, y / b
        r2 = np.minimum(u * u + v * v, 1.0)
        env = (1.0 - r2) ** 2

        def bump(cu, cv, su, sv, amp):
            return amp * np.exp(-0.5 * (((u - cu) / su) ** 2 + ((v - cv) / sv) ** 2))

        features = (bump(0, -0.55, 0.45, 0.2, 0.12)  # forehead
                    + bump(0, 0.0, 0.08, 0.22, 0.28) + bump(0, 0.15, 0.1, 0.08, 0.12)  # nose
                    + bump(-0.42, 0.2, 0.18, 0.16, 0.12) + bump(0.42, 0.2, 0.18, 0.16, 0.12)
                    - bump(-0.32, -0.2, 0.12, 0.08, 0.12) - bump(0.32, -0.2, 0.12, 0.08, 0.12)
                    + bump(0, 0.72, 0.2, 0.1, 0.08))  # chin
        h = self.depth * (0.75 * np.sqrt(1.0 - r2) + env * features)
        return np.maximum(h, 0.0)


@dataclass(frozen=True, eq=False)
class Scene:
    """The surfaces of a scene; surfaces without an object id get the next free ones."""

    surfaces: Sequence[Surface] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        taken = {s.object_id for s in self.surfaces if s.object_id is not None}
        if 0 in taken:
            raise ValueError("object id 0 means 'nothing'; use ids from 1")
        free = (i for i in range(1, len(self.surfaces) + len(taken) + 2) if i not in taken)
        surfaces = tuple(s if s.object_id is not None else
                         dataclasses.replace(s, object_id=next(free)) for s in self.surfaces)
        object.__setattr__(self, "surfaces", surfaces)
        object.__setattr__(self, "_bounded", sum(np.isfinite(s.bound()[1]) for s in surfaces))

    @property
    def ids(self) -> tuple[int, ...]:
        """Object id of each surface."""
        return tuple(int(s.object_id) for s in self.surfaces)

    def cast(self, origin: np.ndarray, dirs: np.ndarray, tmin: float = 0.0
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Nearest hit over all surfaces: ``t`` (inf), surface index (-1), normals (NaN)."""
        n = len(dirs)
        best = np.full(n, np.inf)
        which = np.full(n, -1, np.int64)
        normals = np.full((n, 3), np.nan)
        bundle = _Bundle(origin, dirs, cone=self._bounded > 1)
        for i, surface in enumerate(self.surfaces):
            rays = bundle.candidates(surface)
            if rays is None:
                t, nrm = surface.intersect(origin, dirs, tmin, normals=True)
                rays = np.flatnonzero(t < best)
                t, nrm = t[rays], nrm[rays]
            elif rays.size:
                t, nrm = surface.intersect(origin, dirs[rays], tmin, normals=True)
                closer = t < best[rays]
                rays, t, nrm = rays[closer], t[closer], nrm[closer]
            else:
                continue
            best[rays], which[rays], normals[rays] = t, i, nrm
        return best, which, normals

    def blocked(self, origin: np.ndarray, dirs: np.ndarray, tmax: float,
                dd: np.ndarray | None = None) -> np.ndarray:
        """Whether any surface is hit at ``0 < t < tmax`` along each ray.

        ``dd`` may give the squared lengths of ``dirs`` if they are known.
        """
        out = np.zeros(len(dirs), bool)
        bundle = _Bundle(origin, dirs, dd, cone=self._bounded > 1)
        for surface in self.surfaces:
            rays = bundle.candidates(surface, np.flatnonzero(~out))
            if rays.size:
                t, _ = surface.intersect(origin, dirs[rays], 0.0, normals=False)
                out[rays[t < tmax]] = True
        return out


class _Bundle:
    """Rays from one origin, and the cone that holds them (to skip surfaces quickly)."""

    def __init__(self, origin: np.ndarray, dirs: np.ndarray, dd: np.ndarray | None = None,
                 cone: bool = True) -> None:
        self.origin, self.dirs = origin, dirs
        self.dd = dot(dirs, dirs) if dd is None else dd
        self.axis, self.half = None, np.pi
        if cone and len(dirs):
            axis = (dirs / np.sqrt(self.dd)[:, None]).sum(axis=0)
            norm = np.sqrt(axis @ axis)
            if norm > 0:
                self.axis = axis / norm
                cos = dot(dirs, self.axis) / np.sqrt(self.dd)
                self.half = float(np.arccos(np.clip(cos.min(), -1.0, 1.0))) + 1e-9

    def candidates(self, surface: Surface, among: np.ndarray | None = None) -> np.ndarray | None:
        """Rays (of ``among``) that may hit the surface's bounding sphere (``None``: all)."""
        centre, radius = surface.bound()
        w = centre - self.origin
        dist2 = w @ w
        if not np.isfinite(radius) or dist2 <= radius * radius:
            return among
        if self.axis is not None and self.half < np.pi / 2:
            angle = np.arccos(np.clip(w @ self.axis / np.sqrt(dist2), -1.0, 1.0))
            if angle - np.arcsin(radius / np.sqrt(dist2)) > self.half:
                return np.zeros(0, np.int64)
        dirs, dd = (self.dirs, self.dd) if among is None else (self.dirs[among], self.dd[among])
        along = dot(dirs, w)
        near = (along > 0) & (dist2 * dd - along * along <= (radius * radius * 1.000001) * dd)
        return np.flatnonzero(near) if among is None else among[near]
