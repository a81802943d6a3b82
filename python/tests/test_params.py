"""Editing a loaded scene (facet.traverse / update) and building one from Mitsuba's dictionary
form (facet.load_dict): every result equals a fresh load of the edited XML, bit for bit."""

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


def _box_transform(degrees=20):
    """A rotation about y and a shift, in float32 (what the scene stores)."""
    a = np.radians(np.float32(degrees))
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


def test_environment_scale_and_a_default_value(cornell, tmp_path):
    """An envmap's scale, a parameter the scene leaves at its default: the emitter alone is
    built again (its image is shared, not decoded again), and the render is the edited XML's."""
    materials = cornell.parents[1] / "materials"
    small = dict(res=24, spp=4, max_depth=3)
    scene = facet.load_file(materials / "diffuse.xml", **small)
    before = _render(scene)
    params = facet.traverse(scene)
    assert "emitter_0.scale" not in params.keys()
    params["emitter_0.scale"] = 0.25
    stats = params.update()
    assert stats["objects_created"] == 1 and stats["geometries_built"] == 0
    after = _render(scene)
    preview = (materials / "common" / "preview.xml").read_text()
    envmap = '<string name="filename" value="common/sky.hdr"/>'
    assert envmap in preview
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "preview.xml").write_text(
        preview.replace(envmap, envmap + '<float name="scale" value="0.25"/>'))
    (tmp_path / "diffuse.xml").write_text((materials / "diffuse.xml").read_text())
    fresh = facet.load_file(tmp_path / "diffuse.xml", search_path=[materials], **small)
    assert np.array_equal(after, _render(fresh))
    assert not np.array_equal(after, before)


@pytest.mark.parametrize("two_level", [False, True])
def test_heavy_scene_updates_rebuild_only_what_changed(cornell, tmp_path, two_level):
    """The Cornell box with a 200k-triangle mesh: an edit rebuilds only the objects it touches
    (the mesh is not loaded again). A transform edit builds the whole Embree scene again, or,
    with the scene option embree_two_level, the edited shape's structure and the top level
    alone. The timings are printed (pytest -s), not asserted."""
    ply = tmp_path / "grid.ply"
    assert _write_ply(ply, 317) > 199000
    text = cornell.read_text().replace(
        "</scene>", f'<shape type="ply"><string name="filename" value="{ply}"/>'
        '<ref id="white"/></shape></scene>')
    if two_level:
        text = text.replace('<scene version="3.0.0">', '<scene version="3.0.0">'
                            '<boolean name="embree_two_level" value="true"/>', 1)
        assert "embree_two_level" in text
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
    assert stats["geometries_built"] == 0
    t0 = time.perf_counter()
    image = _render(scene)
    t_render = time.perf_counter() - t0

    moves = []
    for degrees in (10, 20):  # two edits: the second starts from the scene the first left
        t0 = time.perf_counter()
        params["shape_5.to_world"] = _box_transform(degrees)
        stats = params.update()
        moves.append(time.perf_counter() - t0)
        assert stats["shapes_created"] == 1  # the tall box; the 200k-triangle mesh is kept
        assert stats["geometries_built"] == (1 if two_level else 9)
    moved = _render(scene)

    fresh_text = text.replace(RED, '<rgb name="reflectance" value="0.2, 0.6, 0.2"/>').replace(
        LIGHT, '<rgb name="radiance" value="9, 9, 9"/>')
    fresh = _fresh(cornell, tmp_path, fresh_text, "h1.xml")
    assert np.array_equal(image, _render(fresh))
    fresh_text = fresh_text.replace(TALL, TALL + _matrix_xml(_box_transform()))
    assert np.array_equal(moved, _render(_fresh(cornell, tmp_path, fresh_text, "h2.xml")))
    print(f"\nheavy scene{' (two-level)' if two_level else ''}: load {load * 1e3:.1f} ms,"
          f" albedo+radiance update {t_values * 1e3:.2f} ms, render {t_render * 1e3:.1f} ms,"
          f" box transform updates {moves[0] * 1e3:.2f} and {moves[1] * 1e3:.2f} ms")


DICT_TWIN_XML = """<scene version="3.0.0">
    <integrator type="path" id="integrator"><integer name="max_depth" value="5"/>
        <boolean name="hide_emitters" value="false"/></integrator>
    <sensor type="perspective" id="sensor">
        <float name="fov" value="40.0"/>
        <transform name="to_world"><matrix value="-1 0 0 0  0 1 0 1  0 0 -1 4  0 0 0 1"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm" name="film"><integer name="width" value="24"/>
            <integer name="height" value="16"/><string name="pixel_format" value="rgb"/></film>
    </sensor>
    <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.4, 0.5, 0.6"/></bsdf>
    <shape type="sphere" id="ball"><point name="center" value="0.3, 0.5, 0"/>
        <float name="radius" value="0.5"/><ref name="bsdf" id="grey"/></shape>
    <shape type="rectangle" id="floor">
        <transform name="to_world"><matrix value="2 0 0 0  0 0 2 0  0 -2 0 0  0 0 0 1"/></transform>
        <bsdf type="roughconductor" name="bsdf"><string name="material" value="Au"/>
            <float name="alpha" value="0.2"/></bsdf>
    </shape>
    <shape type="rectangle" id="lamp">
        <transform name="to_world"><matrix value="0.5 0 0 0  0 0 -0.5 2  0 0.5 0 0  0 0 0 1"/></transform>
        <emitter type="area" name="emitter">
            <spectrum name="radiance" value="400:3, 500:6, 600:9, 700:5"/></emitter>
    </shape>
    <emitter type="constant" id="sky"><spectrum name="radiance" value="0.25"/></emitter>
</scene>"""


def _twin_dict(floor_matrix):
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 5, "hide_emitters": False},
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "to_world": np.array([[-1, 0, 0, 0], [0, 1, 0, 1], [0, 0, -1, 4], [0, 0, 0, 1]]),
            "sampler": {"type": "independent", "sample_count": 4},
            "film": {"type": "hdrfilm", "width": 24, "height": 16, "pixel_format": "rgb"},
        },
        "grey": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.4, 0.5, 0.6]}},
        "ball": {"type": "sphere", "center": [0.3, 0.5, 0], "radius": 0.5,
                 "bsdf": {"type": "ref", "id": "grey"}},
        "floor": {"type": "rectangle", "to_world": floor_matrix,
                  "bsdf": {"type": "roughconductor", "material": "Au", "alpha": 0.2}},
        "lamp": {"type": "rectangle",
                 "to_world": [[0.5, 0, 0, 0], [0, 0, -0.5, 2], [0, 0.5, 0, 0], [0, 0, 0, 1]],
                 "emitter": {"type": "area", "radiance": {
                     "type": "spectrum", "value": [(400, 3), (500, 6), (600, 9), (700, 5)]}}},
        "sky": {"type": "constant", "radiance": {"type": "spectrum", "value": 0.25}},
    }


class _Matrix:
    """A transform type of one's own: anything with a 4x4 `matrix`."""

    def __init__(self, m):
        self.matrix = m


def test_load_dict_equals_its_xml_twin():
    xml_image = _render(facet.load_string(DICT_TWIN_XML))
    floor = [[2, 0, 0, 0], [0, 0, 2, 0], [0, -2, 0, 0], [0, 0, 0, 1]]
    for m in (floor, np.array(floor, np.float32), _Matrix(np.array(floor))):
        scene = facet.load_dict(_twin_dict(m))
        assert np.array_equal(_render(scene), xml_image)
    # The ids of the scene's children are the dict's keys: traverse() names them so.
    params = facet.traverse(scene)
    assert params["grey.reflectance"] == pytest.approx((0.4, 0.5, 0.6))
    assert params["ball.radius"] == 0.5
    assert params["lamp.emitter.radiance"] == [(400, 3), (500, 6), (600, 9), (700, 5)]


def test_load_dict_cornell_box_equals_the_xml(cornell, tmp_path):
    mesh = cornell.parent / "meshes"
    white = {"type": "ref", "id": "white"}
    d = {"type": "scene",
         "integrator": {"type": "path", "max_depth": 4},
         "sensor": {"type": "perspective", "fov": 37.0,
                    "to_world": [[-1, 0, 0, 0], [0, 1, 0, 1], [0, 0, -1, 4], [0, 0, 0, 1]],
                    "sampler": {"type": "independent", "sample_count": 4},
                    "film": {"type": "hdrfilm", "width": 32, "height": 32}},
         "white": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.73, 0.72, 0.69]}},
         "red": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.62, 0.06, 0.05]}},
         "green": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.13, 0.44, 0.09]}}}
    for name, bsdf in [("floor", white), ("ceiling", white), ("back", white),
                       ("left", {"type": "ref", "id": "red"}),
                       ("right", {"type": "ref", "id": "green"}), ("tall_box", white),
                       ("short_box", white)]:
        d[name] = {"type": "obj", "filename": str(mesh / f"{name}.obj"), "bsdf": bsdf}
    d["light"] = {"type": "obj", "filename": str(mesh / "light.obj"),
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.78}},
                  "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [17, 12, 4]}}}
    # The repository's scene, with the camera's look-at written as the matrix it makes.
    text = cornell.read_text().replace(
        '<lookat origin="0, 1, 4" target="0, 1, 0" up="0, 1, 0"/>',
        '<matrix value="-1 0 0 0  0 1 0 1  0 0 -1 4  0 0 0 1"/>')
    path = tmp_path / "cornell.xml"
    path.write_text(text)
    xml_scene = facet.load_file(path, search_path=[cornell.parent], **SMALL)
    assert np.array_equal(_render(facet.load_dict(d)), _render(xml_scene))


def test_load_dict_errors():
    with pytest.raises(ValueError, match="did you mean 'diffuse'"):
        facet.load_dict({"type": "scene", "b": {"type": "difuse"}})
    with pytest.raises(ValueError, match="b.bsdf: an object needs a 'type'"):
        facet.load_dict({"type": "scene", "b": {"type": "sphere", "bsdf": {"reflectance": 1}}})
    with pytest.raises(ValueError, match="s.center: cannot use"):
        facet.load_dict({"type": "scene", "s": {"type": "sphere", "center": object()}})
    with pytest.raises(facet.Error, match="reference to unknown id"):
        facet.load_dict({"type": "scene", "s": {"type": "sphere",
                                                "bsdf": {"type": "ref", "id": "nope"}}})
