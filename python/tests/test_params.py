"""Editing a loaded scene (facet.traverse / update): every result equals a fresh load of the
edited XML, bit for bit."""

import time

import numpy as np
import pytest

import facet

SMALL = dict(res=32, spp=4, max_depth=4)

RED = '<rgb name="reflectance" value="0.62, 0.06, 0.05"/>'
LIGHT = '<rgb name="radiance" value="17, 12, 4"/>'
TALL = '<string name="filename" value="meshes/tall_box.obj"/>'


def _render(scene):
    return facet.render(scene, seed=11, threads=2).pixels


def _f32(x):
    return repr(float(np.float32(x)))


def _box_transform():
    """A rotation about y and a shift, in float32 (what the scene stores)."""
    a = np.radians(np.float32(20))
    c, s = np.cos(a), np.sin(a)
    m = np.array([[c, 0, s, 0.1], [0, 1, 0, 0], [-s, 0, c, -0.05], [0, 0, 0, 1]], np.float32)
    return m


def _matrix_xml(m):
    return ('<transform name="to_world"><matrix value="' + " ".join(_f32(v) for v in m.ravel())
            + '"/></transform>')


def _fresh(cornell, tmp_path, text, name, params=SMALL):
    path = tmp_path / name
    path.write_text(text)
    return facet.load_file(path, search_path=[cornell.parent], **params)


def test_cornell_box_edits_equal_the_edited_xml(cornell, tmp_path):
    text = cornell.read_text()
    assert RED in text and LIGHT in text and TALL in text
    scene = facet.load_file(cornell, **SMALL)
    original = _render(scene)
    params = facet.traverse(scene)
    assert params["red.reflectance"] == pytest.approx((0.62, 0.06, 0.05))
    assert params.type("shape_7.emitter.radiance") == "rgb"

    # A wall's albedo: the BSDF alone is built again; the meshes and the BVH stay.
    params["red.reflectance"] = (0.1, 0.5, 0.8)
    stats = params.update()
    assert stats["shapes_created"] == 0 and not stats["accel_rebuilt"]
    text = text.replace(RED, '<rgb name="reflectance" value="0.1, 0.5, 0.8"/>')
    first = _render(scene)
    assert np.array_equal(first, _render(_fresh(cornell, tmp_path, text, "a.xml")))
    assert not np.array_equal(first, original)

    # The light's radiance.
    params["shape_7.emitter.radiance"] = [4, 8, 12]
    stats = params.update()
    assert stats["shapes_created"] == 0 and not stats["accel_rebuilt"]
    text = text.replace(LIGHT, '<rgb name="radiance" value="4, 8, 12"/>')
    second = _render(scene)
    assert np.array_equal(second, _render(_fresh(cornell, tmp_path, text, "b.xml")))
    assert not np.array_equal(second, first)

    # The tall box's transform (the scene leaves it at its default): that shape alone is built
    # again.
    m = _box_transform()
    params["shape_5.to_world"] = m
    stats = params.update()
    assert stats["shapes_created"] == 1 and stats["accel_rebuilt"]
    assert np.array_equal(params["shape_5.to_world"], m)
    text = text.replace(TALL, TALL + _matrix_xml(m))
    third = _render(scene)
    assert np.array_equal(third, _render(_fresh(cornell, tmp_path, text, "c.xml")))
    assert not np.array_equal(third, second)


def test_sensor_film_and_integrator_updates(cornell, tmp_path):
    scene = facet.load_file(cornell, **SMALL)
    params = facet.traverse(scene)
    params["sensor.film.width"] = 40
    params["integrator.max_depth"] = 2
    params["sensor.fov"] = 45
    params.update()
    assert scene.film_size() == (40, 32)
    text = cornell.read_text().replace('<integer name="width" value="$res"/>',
                                       '<integer name="width" value="40"/>')
    text = text.replace('value="$max_depth"', 'value="2"').replace(
        '<float name="fov" value="37"/>', '<float name="fov" value="45"/>')
    assert np.array_equal(_render(scene), _render(_fresh(cornell, tmp_path, text, "s.xml", dict(spp=4, res=32))))


def test_keys_types_and_errors(cornell):
    scene = facet.load_file(cornell, **SMALL)
    params = facet.traverse(scene)
    keys = params.keys()
    assert {"white.reflectance", "sensor.to_world", "sensor.film.width",
            "integrator.max_depth", "shape_0.filename"} <= set(keys)
    assert dict(params.items())["sensor.sampler.sample_count"] == 4
    assert isinstance(params["sensor.to_world"], np.ndarray)
    assert "shape_5.to_world" not in params  # at its default: settable, not listed
    with pytest.raises(KeyError, match='did you mean "red.reflectance"'):
        params["red.reflectence"] = (1, 0, 0)
    with pytest.raises(KeyError, match="unknown scene parameter"):
        params["nothing.here"]
    with pytest.raises(TypeError, match="expects an integer"):
        params["sensor.film.width"] = 3.5
    with pytest.raises(TypeError, match="expects a 4x4 matrix"):
        params["sensor.to_world"] = [1, 2, 3]
    with pytest.raises(TypeError, match="expects an rgb triple"):
        params["red.reflectance"] = "red"


def test_update_refused_while_the_scene_renders(cornell):
    scene = facet.load_file(cornell, res=32, spp=1024, max_depth=8)
    params = facet.traverse(scene)
    params["red.reflectance"] = (0.5, 0.5, 0.5)
    import threading

    done = threading.Event()
    t = threading.Thread(target=lambda: (facet.render(scene, threads=1), done.set()))
    t.start()
    time.sleep(0.3)
    try:
        assert not done.is_set(), "the render ended before the update could be tried"
        if True:
            with pytest.raises(facet.Error, match="while a render of it is running"):
                params.update()
    finally:
        t.join()


def _write_ply(path, n):
    """A binary PLY grid of n x n vertices (2 (n-1)^2 triangles) in the box's footprint."""
    u, v = np.meshgrid(np.linspace(-0.6, -0.1, n, dtype=np.float32),
                       np.linspace(-0.6, 0.2, n, dtype=np.float32))
    y = 0.3 + 0.05 * np.sin(u * 40) * np.cos(v * 40)
    verts = np.stack([u, y.astype(np.float32), v], axis=-1).reshape(-1, 3)
    i = np.arange(n * n).reshape(n, n)[:-1, :-1].ravel()
    tris = np.concatenate([np.stack([i, i + 1, i + n], 1), np.stack([i + 1, i + n + 1, i + n], 1)])
    faces = np.zeros(len(tris), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"] = 3
    faces["v"] = tris
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(verts.astype("<f4").tobytes())
        f.write(faces.tobytes())
    return len(tris)


def test_heavy_scene_updates_rebuild_only_what_changed(cornell, tmp_path):
    """The Cornell box with a 200k-triangle mesh: an edit rebuilds only the objects it touches
    (the mesh is not loaded again); the timings are printed (pytest -s), not asserted."""
    ply = tmp_path / "grid.ply"
    assert _write_ply(ply, 317) > 199000
    text = cornell.read_text().replace(
        "</scene>", f'<shape type="ply"><string name="filename" value="{ply}"/>'
        '<ref id="white"/></shape></scene>')
    path = tmp_path / "heavy.xml"
    path.write_text(text)
    t0 = time.perf_counter()
    scene = facet.load_file(path, search_path=[cornell.parent], **SMALL)
    load = time.perf_counter() - t0
    params = facet.traverse(scene)

    t0 = time.perf_counter()
    params["red.reflectance"] = (0.2, 0.6, 0.2)
    params["shape_7.emitter.radiance"] = (9, 9, 9)
    stats = params.update()
    t_values = time.perf_counter() - t0
    assert stats["shapes_created"] == 0 and not stats["accel_rebuilt"]
    t0 = time.perf_counter()
    image = _render(scene)
    t_render = time.perf_counter() - t0

    t0 = time.perf_counter()
    params["shape_5.to_world"] = _box_transform()
    stats = params.update()
    t_move = time.perf_counter() - t0
    assert stats["shapes_created"] == 1  # the tall box; the 200k-triangle mesh is kept
    moved = _render(scene)

    fresh_text = text.replace(RED, '<rgb name="reflectance" value="0.2, 0.6, 0.2"/>').replace(
        LIGHT, '<rgb name="radiance" value="9, 9, 9"/>')
    fresh = _fresh(cornell, tmp_path, fresh_text, "h1.xml")
    assert np.array_equal(image, _render(fresh))
    fresh_text = fresh_text.replace(TALL, TALL + _matrix_xml(_box_transform()))
    assert np.array_equal(moved, _render(_fresh(cornell, tmp_path, fresh_text, "h2.xml")))
    print(f"\nheavy scene: load {load * 1e3:.1f} ms, albedo+radiance update {t_values * 1e3:.2f} ms,"
          f" render {t_render * 1e3:.1f} ms, box transform update {t_move * 1e3:.1f} ms")
