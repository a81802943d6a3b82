"""facet: a physically based renderer for Mitsuba 3 scenes, from Python.

    import facet
    scene = facet.load_file("scenes/cornell-box/scene.xml", spp=64)
    image = facet.render(scene, seed=1)
    pixels = np.asarray(image)        # float32 (height, width, channels)
    image.channels                    # ["R", "G", "B", ...]
    facet.write(image, "cornell.exr")

Errors are ``facet.Error`` (a RuntimeError) whose message starts with the scene location
(``scene.xml:12:5: ...``, also in its ``file``, ``line`` and ``column`` attributes). A render
releases the GIL; Ctrl-C stops it and raises KeyboardInterrupt, whose ``partial`` attribute is
the Image of the passes done.
"""

import os as _os

from . import _facet
from ._facet import Error, Scene, Chi2Result

__all__ = [
    "Error",
    "Scene",
    "Image",
    "Chi2Result",
    "Plugin",
    "load_file",
    "load_string",
    "load_dict",
    "traverse",
    "SceneParameters",
    "scene_info",
    "render",
    "write",
    "read",
    "merge",
    "modes",
    "plugins",
    "add_plugin_dir",
    "chi2",
    "set_log_level",
]


def _param_value(key, value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float, str)):
        return str(value)
    if isinstance(value, _os.PathLike):
        return _os.fspath(value)
    if isinstance(value, (tuple, list)):
        return ",".join(str(v) for v in value)
    raise TypeError(f"scene parameter {key}={value!r}: expected a number, a string or a bool")


def _params(params):
    return {k: _param_value(k, v) for k, v in params.items()}


def _mode(mode):
    if mode is not None and not isinstance(mode, str):
        raise TypeError(f"mode={mode!r}: expected a str such as 'scalar_rgb'")
    return mode


def load_file(path, *, lenient=False, search_path=(), mode=None, **params):
    """Loads a Mitsuba 3 XML scene. Keyword arguments are the ``$name`` values (the ``-D`` options
    of ``facet render``): ``facet.load_file("scene.xml", spp=64, res=256)``. ``lenient`` turns
    unused parameters into warnings, ``search_path`` adds folders for meshes and textures.
    ``mode`` is the colour mode the scene is built for and renders in (``-m`` of ``facet
    render``; ``modes()`` lists them; None: the default), as Mitsuba's ``set_variant`` chooses it
    before a load; the scene's ``mode`` attribute names it."""
    return _facet.load_file(_os.fspath(path), _params(params), lenient,
                            [_os.fspath(p) for p in search_path], _mode(mode))


def scene_info(path, *, lenient=False, search_path=(), mode=None, **params):
    """What a scene file declares, from parsing it alone (no plugin created, no mesh read, no BVH
    built; ``facet info`` on the command line): a dict with ``sensors`` (each a dict of
    ``plugin``, ``film``, ``sampler``, ``film_size`` (width, height) and ``spp``),
    ``integrator``, ``plugins`` (names by kind) and ``mode``."""
    return _facet.scene_info(_os.fspath(path), _params(params), lenient,
                             [_os.fspath(p) for p in search_path], _mode(mode))


def load_string(xml, *, lenient=False, search_path=(), mode=None, **params):
    """Loads a scene given as XML text; locations in errors read ``string:line:col``. The
    arguments are those of ``load_file``."""
    return _facet.load_string(xml, _params(params), lenient,
                              [_os.fspath(p) for p in search_path], _mode(mode))


class SceneParameters:
    """The parameters of a loaded scene (``facet.traverse(scene)``), a mapping from keys such as
    ``"red.reflectance"``, ``"sensor.to_world"`` or ``"shape_7.emitter.radiance"`` (the object's
    id, or its place when it has none, then the parameter) to values: bools, ints, floats,
    strings, rgb and point triples, spectra (a number or (wavelength, value) pairs) and 4x4
    transforms (NumPy arrays).

        params = facet.traverse(scene)
        params["red.reflectance"] = (0.2, 0.3, 0.7)
        params.update()                     # the scene changes in place
        image = facet.render(scene)

    Assigning checks the type; ``update()`` builds again only the objects that depend on the
    changed values (a render afterwards equals a fresh load of the edited scene, bit for bit) and
    returns what it rebuilt. A parameter the scene leaves at its default (a shape's
    ``to_world``, say) is not among ``keys()`` but may be assigned."""

    def __init__(self, native):
        self._native = native

    def keys(self):
        return list(self._native.keys())

    def __iter__(self):
        return iter(self.keys())

    def __len__(self):
        return len(self._native.keys())

    def __contains__(self, key):
        return isinstance(key, str) and self._native.has(key) and self._native.is_set(key)

    def __getitem__(self, key):
        if not isinstance(key, str):
            raise TypeError(f"scene parameter keys are strings, not {type(key).__name__}")
        try:
            return self._native.get(key)
        except Error as e:
            raise KeyError(str(e)) from None

    def __setitem__(self, key, value):
        if not isinstance(key, str):
            raise TypeError(f"scene parameter keys are strings, not {type(key).__name__}")
        try:
            self._native.set(key, value)
        except Error as e:
            if "unknown scene parameter" in str(e):
                raise KeyError(str(e)) from None
            raise TypeError(str(e)) from None

    def get(self, key, default=None):
        return self[key] if key in self else default

    def items(self):
        return [(k, self[k]) for k in self.keys()]

    def values(self):
        return [self[k] for k in self.keys()]

    def type(self, key):
        """The parameter's type: "boolean", "integer", "float", "string", "vector", "rgb",
        "spectrum" or "transform"."""
        return self._native.type(key)

    def update(self):
        """Applies the assignments made since the last update; returns a dict saying what was
        built again (objects_created, shapes_created, shapes_relinked, accel_rebuilt). Raises
        ``facet.Error`` (the scene unchanged) when an object refuses a value or when a render of
        the scene is running."""
        return self._native.update()

    def __repr__(self):
        lines = [f"  {k!r}: {self.type(k)}," for k in self.keys()]
        return "SceneParameters({\n" + "\n".join(lines) + "\n})"


def traverse(scene):
    """The parameters of ``scene`` as a ``SceneParameters`` mapping (see there)."""
    return SceneParameters(_facet.traverse(scene))


def _xml_attr(value):
    from xml.sax.saxutils import quoteattr

    return quoteattr(str(value))


def _xml_number(value):
    return repr(float(value))


def _is_number(value):
    import numbers

    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _matrix(value):
    import numpy as np

    value = getattr(value, "matrix", value)
    if isinstance(value, (str, bytes)) or _is_number(value):
        return None
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    return a if a.shape == (4, 4) else None


def _dict_kinds():
    kinds = {p.name: p.kind for p in plugins()}
    kinds["scene"] = "scene"
    return kinds


def _dict_to_xml(d, kinds, path, name=None, id_=None, indent="    "):
    """One object of Mitsuba's dictionary form as facet XML."""
    plugin = d.get("type")
    if not isinstance(plugin, str):
        raise ValueError(f"{path or 'the scene'}: an object needs a 'type' (a plugin name)")
    kind = kinds.get(plugin)
    if kind is None:
        import difflib

        close = difflib.get_close_matches(plugin, list(kinds), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ValueError(f"{path or 'the scene'}: unknown plugin type {plugin!r}{hint}")
    is_scene = kind == "scene"
    attrs = ""
    if not is_scene:
        attrs = f" type={_xml_attr(plugin)}"
    if "id" in d:
        id_ = d["id"]
    if id_ is not None:
        attrs += f" id={_xml_attr(id_)}"
    if name is not None and not is_scene:
        attrs += f" name={_xml_attr(name)}"
    if is_scene:
        attrs += ' version="3.0.0"'
    out = [f"{indent[4:]}<{kind}{attrs}>"]
    for key, value in d.items():
        if key in ("type", "id"):
            continue
        where = f"{path}.{key}" if path else key
        out.append(_value_to_xml(key, value, kinds, where, indent, top=is_scene))
    out.append(f"{indent[4:]}</{kind}>")
    return "\n".join(out)


def _value_to_xml(key, value, kinds, where, indent, top):
    n = _xml_attr(key)
    if isinstance(value, dict):
        t = value.get("type")
        if t == "ref":
            if "id" not in value:
                raise ValueError(f"{where}: a reference needs an 'id'")
            return f"{indent}<ref name={n} id={_xml_attr(value['id'])}/>"
        if t == "rgb":
            v = value.get("value")
            if _is_number(v):
                v = [v] * 3
            try:
                text = ", ".join(_xml_number(x) for x in v)
                assert len(list(v)) == 3
            except (TypeError, AssertionError):
                raise ValueError(f"{where}: an rgb value needs 3 numbers (or one)") from None
            return f"{indent}<rgb name={n} value={_xml_attr(text)}/>"
        if t == "spectrum":
            if "filename" in value:
                import os

                return (f"{indent}<spectrum name={n} "
                        f"filename={_xml_attr(os.fspath(value['filename']))}/>")
            v = value.get("value")
            if _is_number(v):
                text = _xml_number(v)
            else:
                try:
                    text = ", ".join(f"{_xml_number(w)}:{_xml_number(x)}" for w, x in v)
                except (TypeError, ValueError):
                    raise ValueError(f"{where}: a spectrum value is a number or (wavelength, "
                                     "value) pairs") from None
            return f"{indent}<spectrum name={n} value={_xml_attr(text)}/>"
        # A nested object: at the top of a scene its key is its id (as in Mitsuba), inside
        # an object its property name.
        if top:
            return _dict_to_xml(value, kinds, where, id_=key, indent=indent + "    ")
        return _dict_to_xml(value, kinds, where, name=key, indent=indent + "    ")
    if isinstance(value, bool):
        return f"{indent}<boolean name={n} value=\"{'true' if value else 'false'}\"/>"
    if isinstance(value, int) or type(value).__name__.startswith(("int", "uint")):
        return f"{indent}<integer name={n} value=\"{int(value)}\"/>"
    if _is_number(value):
        return f"{indent}<float name={n} value=\"{_xml_number(value)}\"/>"
    if isinstance(value, str) or isinstance(value, _os.PathLike):
        return f"{indent}<string name={n} value={_xml_attr(_os.fspath(value))}/>"
    m = _matrix(value)
    if m is not None:
        text = " ".join(_xml_number(x) for x in m.ravel())
        return f"{indent}<transform name={n}><matrix value=\"{text}\"/></transform>"
    try:
        import numpy as np

        v = np.asarray(value, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        v = None
    if v is not None and v.size == 3:
        text = ", ".join(_xml_number(x) for x in v)
        return f"{indent}<point name={n} value=\"{text}\"/>"
    raise ValueError(f"{where}: cannot use {type(value).__name__} {value!r} as a scene value "
                     "(expected a bool, number, string, 3 numbers, a 4x4 transform or a dict)")


def dict_to_xml(d):
    """The XML text ``load_dict`` loads for the dictionary ``d``."""
    if not isinstance(d, dict):
        raise TypeError(f"load_dict expects a dict, not {type(d).__name__}")
    return _dict_to_xml(d, _dict_kinds(), "", indent="    ")


def load_dict(d, *, lenient=False, search_path=(), mode=None):
    """Builds a scene from Mitsuba's dictionary form::

        scene = facet.load_dict({
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 6},
            "light": {"type": "point", "position": [0, 2, 0],
                      "intensity": {"type": "rgb", "value": [5, 5, 5]}},
            "red": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.6, 0.1, 0.1]}},
            "ball": {"type": "sphere", "to_world": np.eye(4), "bsdf": {"type": "ref", "id": "red"}},
        })

    Every object is a dict with a ``type`` (a plugin name, or "scene"); the keys of the scene's
    children are their ids, the keys inside an object are property names. Values: bools, ints,
    floats, strings, 3 numbers (a point), 4x4 matrices (nested lists, NumPy arrays, or anything
    with a ``matrix`` attribute) for transforms, ``{"type": "rgb", "value": ...}``,
    ``{"type": "spectrum", "value": ...}`` (a number or (wavelength, value) pairs, or
    ``"filename"``), ``{"type": "ref", "id": ...}`` and nested objects. The dict becomes the
    XML text ``dict_to_xml`` returns and loads like ``load_string`` (relative file names are
    found from the current folder and ``search_path``)."""
    return load_string(dict_to_xml(d), lenient=lenient, search_path=search_path, mode=mode)


class Image(tuple):
    """What ``render`` returns: an array-like (``np.asarray(image)`` is the float32 pixels of shape
    (height, width, channels), named by ``image.channels``) that is also the pair ``(pixels,
    channels)`` (so ``pixels, channels = facet.render(...)`` works) and carries ``metadata`` (the
    attributes the CLI writes into an EXR: the ``facet:`` strings, ``samplesPerPixel`` (int),
    ``renderTimeSeconds`` (float), ``worldToCamera`` and ``worldToNDC`` (4x4 matrices as a tuple
    of rows)), ``half`` (the film's component_format is float16) and ``window``:
    ``(x, y, full_width, full_height)``, where the pixels lie in the whole film (a crop's data
    window inside its display window)."""

    def __new__(cls, pixels, channels, metadata=None, half=False, window=None):
        self = super().__new__(cls, (pixels, list(channels)))
        self.metadata = dict(metadata or {})
        self.half = bool(half)
        h, w = pixels.shape[:2]
        self.window = tuple(int(v) for v in window) if window is not None else (0, 0, w, h)
        return self

    def __reduce__(self):
        return (Image, (self[0], self[1], self.metadata, self.half, self.window))

    def to_part(self):
        """A plain dict of everything (for sending a part between processes)."""
        return dict(pixels=self[0], channels=list(self[1]), metadata=dict(self.metadata),
                    half=self.half, window=self.window)

    @classmethod
    def from_part(cls, part):
        return cls(part["pixels"], part["channels"], part["metadata"], part["half"],
                   part["window"])

    def __array__(self, dtype=None, copy=None):
        import numpy as np
        pixels = self[0]
        if dtype is not None and np.dtype(dtype) != pixels.dtype:
            return pixels.astype(dtype)
        return pixels.copy() if copy else pixels

    @property
    def pixels(self):
        return self[0]

    @property
    def channels(self):
        return self[1]

    @property
    def shape(self):
        return self[0].shape

    def __repr__(self):
        h, w, c = self[0].shape
        return f"<facet.Image {w}x{h} {self[1]}>"


def render(scene, spp=None, seed=0, sensor=0, threads=None, crop=None, pass_index=None, passes=1,
           progress=None, mode=None):
    """Renders ``sensor`` of ``scene`` with its integrator and returns an ``Image``: a NumPy
    float32 array of shape (height, width, channels) and the channel names (R, G, B, then A and
    the AOVs when the scene asks for them). ``spp`` overrides the sampler's sample_count, ``seed``
    is added to the sampler's seed, ``threads`` defaults to every core. The same scene, seed and
    spp give the same pixels for any thread count, and the same pixels as ``facet render``.

    ``crop=(x0, y0, x1, y1)`` renders only film pixels [x0, x1) x [y0, y1) (the same pixels as
    in a render of the whole film); ``pass_index=i, passes=n`` renders part i of n of a render
    of n x spp samples per pixel (``--pass``/``--passes`` of the CLI), with the raw sums of its
    pixels as extra ``facet.*`` channels. ``facet.merge`` puts such parts back together.
    ``passes=n`` without ``pass_index`` renders all n parts here, combined as their merge
    combines them (bit-identical to it).

    ``progress`` is a callable, called on this thread with the fraction done (0 to 1, rising,
    1 at the end; an exception it raises stops the render and is raised here), or a bool: draw
    the CLI's progress bar on stderr. None (the default) draws it when stderr is a terminal.

    The render is in the colour mode the scene was loaded in (``load_file``'s ``mode``; the
    image's ``facet:mode`` metadata names it). ``mode``, by Mitsuba's variant names (``modes()``
    lists facet's; the ``llvm_``, ``cuda_`` and ``_ad_`` names stand for the scalar mode, with a
    note), checks it: a mode facet does not render, or another than the scene's, raises
    ``facet.Error`` before the render."""
    _mode(mode)
    if progress is None:
        import sys
        progress = bool(getattr(sys.stderr, "isatty", lambda: False)())
    elif not callable(progress):
        progress = bool(progress)
    if pass_index is None:
        pass_index = -1 if int(passes) > 1 else 0
    if threads is not None:
        # Beyond the cores the count is capped with a warning; so it is beyond a C int.
        threads = min(int(threads), 2**31 - 1)
    pixels, channels, metadata, half, window = _facet.render(
        scene, spp, int(seed), int(sensor), threads,
        None if crop is None else [int(v) for v in crop], int(pass_index), int(passes), progress,
        mode)
    return Image(pixels, channels, metadata, half, window)


def merge(parts, output=None):
    """Merges the parts of a split render as ``facet merge`` does: crop windows placed where they
    belong, passes combined by their raw sums (Σ w·L / Σ w over all their samples, whatever the
    filter); with one pass the pixels are the parts' pixels. ``parts`` are file names or rendered ``Image``s (mixed as you like). Raises
    ``facet.Error`` naming the parts that overlap, leave holes or belong to different renders.
    Returns the whole image (and writes it to ``output`` when given)."""
    items = []
    for p in parts:
        if isinstance(p, (str, _os.PathLike)):
            items.append(_os.fspath(p))
        elif isinstance(p, Image):
            items.append((p[0], list(p[1]), dict(p.metadata), p.half, list(p.window)))
        elif isinstance(p, dict):
            items.append((p["pixels"], list(p["channels"]), dict(p["metadata"]), bool(p["half"]),
                          list(p["window"])))
        else:
            raise TypeError(f"cannot merge {type(p).__name__}: expected a file name or a facet.Image")
    pixels, channels, metadata, half, window, _passes = _facet.merge(items)
    image = Image(pixels, channels, metadata, half, window)
    if output is not None:
        write(image, output)
    return image


def write(image, path, channels=None, *, half=None, metadata=None, ocio_config="", display="",
          view="", look=""):
    """Writes an image through facet's writer (the one ``facet render`` uses): ``.exr`` keeps every
    channel (float16 when the film says so, else float32), ``.hdr``/``.pfm`` are linear, ``.png``
    and ``.jpg`` go through the OpenColorIO display transform. ``image`` is what ``render``
    returns, a ``(pixels, channels)`` pair or an array (channels then default to R, G, B, A or Y).
    ``ocio_config``, ``display``, ``view`` and ``look`` are the CLI's ``--ocio-config``,
    ``--display``, ``--view`` and ``--look`` (empty: $OCIO or facet's config, its default display,
    that display's default view, the view's own looks).
    """
    import numpy as np

    meta = {}
    film_half = False
    window = None
    if isinstance(image, Image):
        meta.update(image.metadata)
        film_half = image.half
        window = image.window
    if isinstance(image, tuple):
        pixels, names = image[0], image[1]
    else:
        pixels, names = image, None
    if channels is not None:
        names = list(channels)
    pixels = np.ascontiguousarray(pixels, dtype=np.float32)
    if names is None:
        c = 1 if pixels.ndim == 2 else pixels.shape[2]
        names = ["Y"] if c == 1 else list("RGBA"[:c]) if c <= 4 else []
    if metadata:
        meta.update({str(k): str(v) for k, v in metadata.items()})
    if window is None:
        window = (0, 0, pixels.shape[1], pixels.shape[0])
    _facet.write(pixels, list(names), _os.fspath(path), film_half if half is None else bool(half), meta,
                 _os.fspath(ocio_config), display, view, look, list(window))


def read(path):
    """Reads an image (any format OpenImageIO knows) as ``(pixels, channels)``, pixels float32 of
    shape (height, width, channels)."""
    pixels, channels = _facet.read(_os.fspath(path))
    return pixels, channels


class Plugin(tuple):
    """One plugin: ``(name, kind, description)``, and ``doc``, its parameter table."""

    def __new__(cls, name, kind, description, doc):
        self = super().__new__(cls, (name, kind, description))
        self.doc = doc
        return self

    name = property(lambda self: self[0])
    kind = property(lambda self: self[1])
    description = property(lambda self: self[2])


def modes():
    """The colour modes facet renders in, by Mitsuba's variant names, the default first:
    ``["scalar_rgb"]``."""
    return list(_facet.modes())


def plugins(kind=None):
    """The plugins on the search path as ``Plugin`` tuples ``(name, kind, description)``, sorted
    by name; ``kind`` ("bsdf", "emitter", ...) keeps one kind."""
    out = [Plugin(*p) for p in _facet.plugins()]
    if kind is not None:
        out = [p for p in out if p.kind == kind]
    return out


def add_plugin_dir(path):
    """Adds a folder to the plugin search path (``-a`` of the CLI)."""
    _facet.add_plugin_dir(_os.fspath(path))


def set_log_level(level):
    """"trace", "debug", "info" (the default), "warn", "error" or "off"."""
    _facet.set_log_level(level)


def _entries(params):
    out = []
    for key, value in params.items():
        if isinstance(value, bool):
            value = "true" if value else "false"
        elif isinstance(value, (tuple, list)):
            value = ",".join(str(v) for v in value)
        out.append(f"{key}={value}")
    return out


def chi2(kind, name=None, *, xml=None, theta=30.0, phi=0.0, wi=None, ref=(0.25, -0.5, 1.5),
         shape="rectangle", emission=False, component=None, mode="radiance", alpha=0.1,
         alpha_v=None, visible=True, res=32, samples=1000000, seed=0, tests=1, significance=0.01,
         adaptive=True, ires=7, colour_mode=None, **params):
    """The chi-square test of ``facet chi2`` (facet::testing): draws ``samples`` directions from a
    plugin and compares their histogram over (phi, cos theta) with its pdf.

        r = facet.chi2("bsdf", "roughconductor", distribution="ggx", alpha=0.2, theta=60)
        r.passed, r.statistic, r.dof, r.p_value, r.observed, r.expected

    ``kind`` is "bsdf", "emitter" or "microfacet". Plugin parameters are keyword arguments (a
    number becomes a float, a bool a boolean, a 3-tuple an rgb; "integer:name" keys name the
    type) or ``xml`` gives the object. BSDFs are seen from ``theta``/``phi`` (degrees) or ``wi``;
    emitters from ``ref`` (or their emitted rays with ``emission=True``); microfacet
    distributions ("beckmann" or "ggx" as ``name``) take ``alpha``, ``alpha_v`` and ``visible``.
    ``observed`` and ``expected`` are arrays of shape (res, 2 res), cos theta = -1 in row 0.
    ``colour_mode`` builds the BSDF or emitter in that colour mode (``-m`` of ``facet chi2``; a
    plastic's lobe weights come from its colours); ``mode`` is the transport mode.
    """
    opts = dict(res=int(res), samples=int(samples), seed=int(seed), tests=int(tests),
                significance=float(significance), adaptive=bool(adaptive), ires=int(ires))
    if wi is not None and (theta != 30.0 or phi != 0.0):
        raise ValueError("give the incident direction either as wi or as theta/phi")
    direction = list(wi) if wi is not None else _facet.direction_from_angles(theta, phi)
    if kind == "bsdf":
        if xml is not None:
            if params or name is not None:
                raise ValueError("give the BSDF either by name and parameters or as xml")
            text = xml
        else:
            if name is None:
                raise ValueError("name the BSDF plugin to test (or give xml)")
            text = _facet.chi2_object_xml("bsdf", name, _entries(params))
        return _facet.chi2_bsdf(text, direction, mode, -1 if component is None else int(component),
                                opts, _mode(colour_mode))
    if kind == "emitter":
        if xml is not None:
            if params or name is not None:
                raise ValueError("give the emitter either by name and parameters or as xml")
            scene = xml if "<scene" in xml else f'<scene version="3.0.0">{xml}</scene>'
        else:
            if name is None:
                raise ValueError("name the emitter plugin to test (or give xml)")
            scene = _facet.chi2_emitter_scene_xml(name, _entries(params), shape)
        return _facet.chi2_emitter(scene, list(ref), bool(emission), opts, _mode(colour_mode))
    if kind == "microfacet":
        if name not in ("beckmann", "ggx"):
            raise ValueError(f"microfacet distribution {name!r}: expected 'beckmann' or 'ggx'")
        if params:
            raise ValueError(f"unknown microfacet arguments: {', '.join(params)}")
        av = alpha if alpha_v is None else alpha_v
        return _facet.chi2_microfacet(name, float(alpha), float(av), bool(visible), direction, opts)
    raise ValueError(f"chi2 kind {kind!r}: expected 'bsdf', 'emitter' or 'microfacet'")
