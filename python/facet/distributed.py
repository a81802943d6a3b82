"""Renders split across the workers of a Dask cluster, merged to the exact image.

    from dask.distributed import Client
    import facet.distributed

    client = Client("scheduler:8786")             # or Client(LocalCluster(n_workers=2))
    image = facet.distributed.render("scene.xml", client, tiles=(4, 2), passes=2, spp=64)
    facet.write(image, "scene.exr")

The film is cut into ``tiles`` crop windows (columns, rows) and each window into ``passes`` parts
of ``spp`` samples per pixel; every (window, pass) is one task that loads the scene on its worker
and renders that part. A worker keeps the last few scenes it loaded, each under the content hash
of its files (the scene file, the files it includes and the meshes, images and spectra they
name): a scene edited between two renders is loaded anew, and a worker whose files differ from
the client's refuses the task. The parts come back as arrays and are
merged as ``facet merge`` merges files: windows placed where they belong, passes combined by their
raw sums (Σ w·L / Σ w over all their samples, whatever the filter). The result is bit-identical to
``facet.render(scene, passes=passes)`` of the whole film in one process (with one pass: to
``facet.render(scene)``), the same estimator as one render of passes x spp samples per pixel.
The workers must see the scene file and its assets at the same path (a shared folder, or the same machine).
"""

import collections
import hashlib
import os
import re
import xml.etree.ElementTree as ElementTree

import facet

__all__ = ["render", "tile_windows", "render_part", "scene_hash"]

# (path, params, mode) -> (content hash, scene), least recently used first; at most _CACHE_SIZE.
_CACHE_SIZE = 4
_scenes = collections.OrderedDict()


def tile_windows(width, height, tiles):
    """The crop windows (x0, y0, x1, y1) that cut a width x height film into ``tiles`` = (columns,
    rows) (an int n means n x n), row by row; sizes differ by at most one pixel."""
    if isinstance(tiles, int):
        tiles = (tiles, tiles)
    cols, rows = int(tiles[0]), int(tiles[1])
    if cols < 1 or rows < 1 or cols > width or rows > height:
        raise ValueError(f"tiles={tiles!r}: expected 1..{width} columns and 1..{height} rows")
    xs = [width * i // cols for i in range(cols + 1)]
    ys = [height * j // rows for j in range(rows + 1)]
    return [(xs[i], ys[j], xs[i + 1], ys[j + 1]) for j in range(rows) for i in range(cols)]


_PARAM = re.compile(r"\$([A-Za-z_][A-Za-z0-9_]*)")


def _scene_files(path, params):
    """The scene file and the files it names, as the loader finds them: included files (and what
    they name), and every ``filename`` (meshes, images, spectra), with ``$name`` values replaced.
    Where a relative name could resolve in several folders, every existing candidate counts."""
    path = os.path.abspath(path)
    files, folders, names, todo = [], [os.path.dirname(path)], [], [path]
    while todo:
        current = todo.pop()
        if current in files or not os.path.isfile(current):
            continue  # seen, or missing (the load says so)
        files.append(current)
        try:
            root = ElementTree.parse(current).getroot()
        except (ElementTree.ParseError, OSError, ValueError):
            continue  # not XML (the load says so): its bytes alone count
        here = os.path.dirname(current)
        values = dict(params)
        for el in root.iter("default"):
            values.setdefault(el.get("name", ""), el.get("value", ""))

        def expand(text):
            return _PARAM.sub(lambda m: str(values.get(m.group(1), m.group(0))), text)

        folders += [os.path.join(here, expand(el.get("value", ""))) for el in root.iter("path")]
        for el in root.iter():
            if el.get("filename"):
                name = expand(el.get("filename"))
            elif el.get("name", "").endswith("filename") and el.get("value"):
                name = expand(el.get("value"))
            else:
                continue
            found = [os.path.abspath(os.path.join(f, name)) for f in [here] + folders]
            found = [f for f in dict.fromkeys(found) if os.path.isfile(f)]
            if el.tag == "include":
                todo += found
            else:
                names += found
    return sorted(set(files + names))


def scene_hash(scene_path, params=None):
    """Hex digest of the contents of a scene's files (see ``_scene_files``) and its ``params``:
    it changes when any of them is edited."""
    params = {k: facet._param_value(k, v) for k, v in (params or {}).items()}
    h = hashlib.blake2b(digest_size=16)
    for key in sorted(params):
        h.update(f"{key}={params[key]}\0".encode())
    for name in _scene_files(os.fspath(scene_path), params):
        h.update(name.encode() + b"\0")
        with open(name, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        h.update(b"\0")
    return h.hexdigest()


def _scene(path, params, content_hash, mode=None):
    """The worker's scene for (path, params) in colour mode ``mode`` whose files hash to
    ``content_hash`` (None: as they are now), loaded again when they have changed; the least
    recently used beyond _CACHE_SIZE go."""
    key = (path, tuple(sorted(params.items())), mode)
    if content_hash is None:
        content_hash = scene_hash(path, params)
    entry = _scenes.get(key)
    if entry is not None and entry[0] == content_hash:
        _scenes.move_to_end(key)
        return entry[1]
    _scenes.pop(key, None)  # an older version: replaced
    scene = facet.load_file(path, mode=mode, **params)
    # After the load: the files it read are the ones hashed (or an edit since shows).
    mine = scene_hash(path, params)
    if mine != content_hash:
        raise RuntimeError(
            f"{path}: the scene's files on this worker differ from the client's (edited while "
            "the render was submitted, or another copy of them): render again")
    _scenes[key] = (mine, scene)
    while len(_scenes) > _CACHE_SIZE:
        _scenes.popitem(last=False)
    return scene


def _worker_threads():
    """The threads of the Dask worker this task runs on (its ``nthreads``, the
    ``threads_per_worker`` of a LocalCluster), or None outside a worker (every core)."""
    try:
        from distributed import get_worker

        worker = get_worker()
        state = getattr(worker, "state", None)  # distributed >= 2022.11 keeps it there
        n = int(state.nthreads if state is not None else worker.nthreads)
    except Exception:
        return None
    return n if n > 0 else None


def render_part(scene_path, params, crop, pass_index, passes, spp=None, seed=0, sensor=0,
                threads=None, content_hash=None, mode=None):
    """One task: renders window ``crop`` of pass ``pass_index`` of ``passes`` in colour mode
    ``mode`` (None: the default) and returns it as a plain dict (what ``facet.merge`` takes back
    with ``facet.Image.from_part``). ``content_hash`` is the client's ``scene_hash()`` of the
    scene: the worker checks its files against it."""
    scene = _scene(scene_path, params, content_hash, mode)
    if threads is None:
        threads = _worker_threads()
    image = facet.render(scene, spp=spp, seed=seed, sensor=sensor, threads=threads, crop=crop,
                         pass_index=pass_index, passes=passes, progress=False)
    return image.to_part()


def render(scene_path, client, tiles=(2, 2), passes=1, spp=None, seed=0, sensor=0, threads=None,
           params=None, output=None, mode=None):
    """Renders ``scene_path`` on the workers of the Dask ``client`` and returns the merged
    ``facet.Image``; writes it to ``output`` too when given. ``params`` are the scene's ``$name``
    values (``-D``), ``threads`` the threads of each task (default: its worker's ``nthreads``,
    the ``threads_per_worker`` of a LocalCluster), ``mode`` the colour mode (``-m``; None: the
    default)."""
    scene_path = os.path.abspath(os.fspath(scene_path))
    params = {k: facet._param_value(k, v) for k, v in (params or {}).items()}
    if int(passes) < 1:
        raise ValueError(f"passes={passes!r}: expected at least 1")
    # The hash first: an edit while the client parses the scene then shows on the workers.
    content_hash = scene_hash(scene_path, params)
    # The film size, from parsing the scene (no plugin, mesh or BVH on the client).
    info = facet.scene_info(scene_path, mode=mode, **params)  # also checks the mode here
    mode = info["mode"]
    sensors = info["sensors"]
    if not 0 <= int(sensor) < len(sensors):
        raise facet.Error(f"sensor {sensor}: the scene has {len(sensors)} sensors")
    width, height = sensors[int(sensor)]["film_size"]
    windows = tile_windows(width, height, tiles)
    futures = [
        client.submit(render_part, scene_path, params, crop, p, int(passes), spp, seed, sensor,
                      threads, content_hash, mode, pure=False)
        for p in range(int(passes))
        for crop in windows
    ]
    parts = client.gather(futures)
    merged = facet.merge([facet.Image.from_part(p) for p in parts])
    if output is not None:
        facet.write(merged, output)
    return merged
