"""Measurements on Helios geometry: vertices, fruit bodies, principal extents, berries, leaves.

Pure functions of a Helios Context and object ids; :mod:`davis_ag.scene.plants` turns them into a
plant's measured phenotype.
"""

from __future__ import annotations

import numpy as np


def primitive_vertices(context, uuids: list[int]) -> list[np.ndarray]:
    """Vertices of each primitive, as (n, 3) arrays, fetched in one native call."""
    if not uuids:
        return []
    flat, offsets = context.getPrimitiveVertices(list(uuids))
    flat = np.asarray(flat, dtype=np.float64).reshape(-1, 3)
    bounds = [*list(np.asarray(offsets, dtype=np.int64) // 3), len(flat)]
    return [flat[bounds[i] : bounds[i + 1]] for i in range(len(uuids))]


def fruit_body_uuids(context, object_id: int) -> list[int]:
    """The fruit itself: Helios builds the green calyx and stalk into fruit objects; drop them.

    Fruit bodies are textured (strawberry) or coloured red or dark blue (tomato, grape berries);
    calyx, stalk and rachis are untextured green.
    """
    uuids = list(context.getObjectPrimitiveUUIDs(object_id))
    if not uuids:
        return uuids
    textured = np.array([bool(t) for t in context.getPrimitiveTextureFile(uuids)])
    colours = np.asarray(context.getPrimitiveColor(uuids), dtype=float).reshape(-1, 3)
    green = (colours[:, 1] > colours[:, 0]) & (colours[:, 1] >= colours[:, 2])
    body = [u for u, keep in zip(uuids, textured | ~green) if keep]
    return body or uuids


def object_vertices(context, object_id: int) -> np.ndarray:
    """All vertices of a Helios object, (n, 3)."""
    parts = primitive_vertices(context, context.getObjectPrimitiveUUIDs(object_id))
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def principal_extents(points: np.ndarray) -> np.ndarray:
    """Extents of a point set along its principal axes, largest first."""
    centred = points - points.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    projected = centred @ axes.T
    return np.sort(projected.max(axis=0) - projected.min(axis=0))[::-1]


def fruit_radius(points: np.ndarray) -> float:
    """Half the mean principal extent: the radius for a sphere, a mean radius for a cone."""
    return float(principal_extents(points).mean() / 2.0)


def berry_radii(context, object_id: int) -> np.ndarray:
    """Radii of the single berries of a grape cluster, split by mesh connectivity."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    triangles = primitive_vertices(context, fruit_body_uuids(context, object_id))
    if not triangles:
        return np.zeros(0)
    corners = np.concatenate(triangles)
    # Berries share no vertices with each other, triangles of one berry do.
    _, vertex_ids = np.unique(np.round(corners, 7), axis=0, return_inverse=True)
    vertex_ids = vertex_ids.ravel()
    sizes = np.array([len(t) for t in triangles])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    rows = np.repeat(vertex_ids[starts], sizes)
    count = int(vertex_ids.max()) + 1
    graph = coo_matrix((np.ones(len(rows)), (rows, vertex_ids)), shape=(count, count))
    _, labels = connected_components(graph, directed=False)
    berry_of_corner = labels[vertex_ids]
    corner_count = np.bincount(berry_of_corner).astype(float)
    centres: np.ndarray = np.stack(
        [np.bincount(berry_of_corner, weights=corners[:, axis]) for axis in range(3)], axis=1
    )
    centres /= corner_count[:, None]
    spread = np.linalg.norm(corners - centres[berry_of_corner], axis=1)
    radii = np.bincount(berry_of_corner, weights=spread) / corner_count
    return radii[corner_count >= 12]  # stray stem pieces are not berries


def leaf_length(points: np.ndarray) -> float:
    """Extent of a leaf blade along its principal axis."""
    return float(principal_extents(points)[0])


def leaf_groups(blade_ids: list[int], blades_per_leaf: int) -> list[list[int]]:
    """Group blade object ids into leaves: runs of consecutive ids, cut every ``blades_per_leaf``."""
    groups: list[list[int]] = []
    for blade in sorted(blade_ids):
        if groups and blade == groups[-1][-1] + 1 and len(groups[-1]) < blades_per_leaf:
            groups[-1].append(blade)
        else:
            groups.append([blade])
    return groups
