#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (tests/data/fuzz/<target>/corpus/) and the xml
target's dictionary (tests/data/fuzz/xml/xml.dict) from the repository's scenes, meshes and
textures, plus small hand-made files for the formats the repository has no example of. Run from
anywhere; the output is committed. Needs oiiotool for the image seeds.

    python3 tests/fuzz/make_corpus.py
"""
import glob
import os
import re
import shutil
import struct
import subprocess
import tempfile
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "tests", "data", "fuzz")


def out_dir(target):
    d = os.path.join(OUT, target, "corpus")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return d


def write(d, name, data):
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# --- xml: every scene of the repository, its films shrunk to 8 x 8 and comments dropped --------
def xml_corpus():
    d = out_dir("xml")
    scenes = sorted(glob.glob(os.path.join(ROOT, "scenes", "**", "*.xml"), recursive=True) +
                    glob.glob(os.path.join(ROOT, "tests", "compat", "data", "peer-scenes", "**",
                                           "*.xml"), recursive=True))
    for path in scenes:
        text = open(path, encoding="utf-8").read()
        text = re.sub(r"<!--.*?-->", "", text, flags=re.S)
        text = re.sub(r'(<(?:integer|default) name="(?:width|height|res|resolution)" value=")[^"]*"',
                      r'\g<1>8"', text)
        text = re.sub(r'(<(?:integer|default) name="(?:crop_width|crop_height)" value=")[^"]*"',
                      r'\g<1>4"', text)
        text = re.sub(r"\n\s*\n", "\n", text)
        rel = os.path.relpath(path, ROOT).replace(os.sep, "_")
        write(d, rel, text)
    write(d, "minimal.xml", '<scene version="3.0.0"><shape type="sphere"/></scene>')


# --- obj ---------------------------------------------------------------------------------------
def obj_corpus():
    d = out_dir("obj")
    for path in sorted(glob.glob(os.path.join(ROOT, "scenes", "**", "*.obj"), recursive=True) +
                       glob.glob(os.path.join(ROOT, "tests", "compat", "data", "meshes", "*.obj"))):
        shutil.copy(path, os.path.join(d, os.path.basename(path)))
    write(d, "indices.obj",
          "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
          "f 1/1/1 2/2/1 3/3/1 4/4/1\nf -4//-1 -3//-1 -2//-1\ng g\ns 1\nf 1/1 3/3 4/4 # c\n")


# --- ply: the teapot cut to a few faces, in the three encodings, with attributes and lists ------
def ply_corpus():
    d = out_dir("ply")
    verts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
    header = ("ply\nformat {}\ncomment seed\nelement vertex 4\nproperty float x\n"
              "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
              "property float nz\nproperty float u\nproperty float v\nproperty uchar red\n"
              "property uchar green\nproperty uchar blue\nproperty float w_0\n"
              "element face 2\nproperty list uchar int vertex_indices\nproperty float q_x\n"
              "element extra 1\nproperty list ushort double stuff\nend_header\n")
    text = header.format("ascii 1.0")
    for i, (x, y, z) in enumerate(verts):
        text += f"{x} {y} {z} 0 0 1 {x} {y} {50 * i} 20 30 0.5\n"
    text += "3 0 1 2 0.25\n4 0 2 3 1 0.5\n2 1.5 2.5\n"
    write(d, "ascii.ply", text)
    for fmt, e in (("binary_little_endian 1.0", "<"), ("binary_big_endian 1.0", ">")):
        b = header.format(fmt).encode()
        for i, (x, y, z) in enumerate(verts):
            b += struct.pack(e + "8f3Bf", x, y, z, 0, 0, 1, x, y, 50 * i, 20, 30, 0.5)
        b += struct.pack(e + "B3if", 3, 0, 1, 2, 0.25) + struct.pack(e + "B4if", 4, 0, 2, 3, 1, 0.5)
        b += struct.pack(e + "H2d", 2, 1.5, 2.5)
        write(d, fmt.split()[0] + ".ply", b)
    # The first lines of the teapot: a real file's header and layout.
    teapot = open(os.path.join(ROOT, "tests", "compat", "data", "meshes", "teapot.ply")).read()
    head, body = teapot.split("end_header\n", 1)
    lines = body.splitlines()
    nv = int(re.search(r"element vertex (\d+)", head).group(1))
    head = re.sub(r"element vertex \d+", "element vertex 12", head)
    head = re.sub(r"element face \d+", "element face 4", head)
    faces = ["3 0 1 2", "3 0 2 3", "4 4 5 6 7", "3 8 9 10"]
    write(d, "teapot_cut.ply", head + "end_header\n" + "\n".join(lines[:12] + faces) + "\n")
    assert nv > 12


# --- serialized: versions 3 and 4, single and double precision, all optional arrays -------------
def serialized_file(meshes, version):
    out = b""
    offsets = []
    for name, flags, pos, nrm, uv, col, faces in meshes:
        offsets.append(len(out))
        out += struct.pack("<HH", 0x041C, version)
        dbl = flags & 0x2000
        real = "d" if dbl else "f"
        raw = struct.pack("<I", flags)
        if version == 4:
            raw += name.encode() + b"\0"
        raw += struct.pack("<QQ", len(pos) // 3, len(faces) // 3)
        for arr in (pos, nrm, uv, col):
            raw += struct.pack("<%d%s" % (len(arr), real), *arr)
        raw += struct.pack("<%dI" % len(faces), *faces)
        out += zlib.compress(raw)
    for o in offsets:
        out += struct.pack("<Q" if version == 4 else "<I", o)
    return out + struct.pack("<I", len(meshes))


def serialized_corpus():
    d = out_dir("serialized")
    pos = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]
    nrm = [0, 0, 1] * 4
    uv = [0, 0, 1, 0, 1, 1, 0, 1]
    col = [1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1]
    faces = [0, 1, 2, 0, 2, 3]
    quad = ("quad", 0x1000 | 0x1 | 0x2 | 0x8, pos, nrm, uv, col, faces)
    tri = ("tri", 0x1000 | 0x10, pos[:9], [], [], [], faces[:3])
    write(d, "v4_float.serialized", serialized_file([quad, tri], 4))
    write(d, "v3_double.serialized",
          serialized_file([("", 0x2000 | 0x1, pos, nrm, [], [], faces)], 3))


# --- image: one selector byte (extension and plugin, see image.cpp) + a small file --------------
EXTENSIONS = [".exr", ".png", ".hdr", ".pfm", ".jpg", ".tga", ".bmp", ".tif"]


def image_corpus():
    d = out_dir("image")
    files = [os.path.join(ROOT, "tests", "compat", "data", "textures", "noise_8x8.png"),
             os.path.join(ROOT, "tests", "compat", "data", "textures", "gradient.jpg")]
    files += sorted(glob.glob(os.path.join(ROOT, "tests", "chi2", "*.exr")))
    tmp = tempfile.mkdtemp()
    # OpenImageIO 2.4 has no PFM writer: a 2 x 1 RGB float map by hand.
    pfm = os.path.join(tmp, "pattern.pfm")
    with open(pfm, "wb") as f:
        f.write(b"PF\n2 1\n-1.0\n" + struct.pack("<6f", 0.25, 0.5, 1, 2, 0, 0.125))
    files.append(pfm)
    for ext in EXTENSIONS:
        if ext == ".pfm":
            continue
        p = os.path.join(tmp, "pattern" + ext)
        subprocess.run(["oiiotool", "--nosoftwareattrib", "--pattern",
                        "checker:width=2:height=2", "4x3", "3", "-o", p], check=True)
        files.append(p)
    tiled = os.path.join(tmp, "tiled.exr")
    subprocess.run(["oiiotool", "--nosoftwareattrib", "--pattern", "fill:color=0.5,0.25,1",
                    "20x12", "4", "--tile", "8", "8", "-d", "half", "-o", tiled], check=True)
    files.append(tiled)
    for path in files:
        data = open(path, "rb").read()
        if len(data) > 16384:
            continue
        ext = os.path.splitext(path)[1].lower()
        ext = ".jpg" if ext == ".jpeg" else ext
        index = EXTENSIONS.index(ext)
        base = os.path.basename(path)
        for plugin in range(3):  # read_image, bitmap, envmap
            write(d, f"{plugin}_{base}", bytes([index + 8 * plugin]) + data)
    shutil.rmtree(tmp)


# --- the XML dictionary: tags, attributes, plugin names, parameter names --------------------------
TAGS = ["scene", "bsdf", "emitter", "integrator", "shape", "sensor", "film", "sampler", "texture",
        "rfilter", "medium", "phase", "volume", "spectrum", "rgb", "float", "integer", "boolean",
        "string", "point", "vector", "transform", "translate", "rotate", "scale", "matrix",
        "lookat", "ref", "default", "include", "alias", "path"]
ATTRIBUTES = ["version", "type", "id", "name", "value", "filename", "x", "y", "z", "angle",
              "origin", "target", "up", "as"]


def write_dict():
    words = set()
    for t in TAGS:
        words.update({"<" + t, "</" + t + ">", t})
    for a in ATTRIBUTES:
        words.add(a + '="')
    for path in glob.glob(os.path.join(ROOT, "plugins", "*", "*.cpp")):
        words.add(os.path.splitext(os.path.basename(path))[0])
        # Parameter names read by the plugin: props.get_<type>("name" ...)
        words.update(re.findall(r'props\.get_\w+\(\s*"([a-z_0-9]+)"',
                                open(path, encoding="utf-8").read()))
    words.update(["true", "false", "0", "1", "-1", "0.5", "1e-3", "inf", "nan", "$", "/>", ">",
                  "3.0.0", "0 0 1", "1, 2, 3", "400:1, 700:2"])
    os.makedirs(os.path.join(OUT, "xml"), exist_ok=True)
    with open(os.path.join(OUT, "xml", "xml.dict"), "w") as f:
        f.write("# libFuzzer dictionary of the xml target (written by make_corpus.py)\n")
        for w in sorted(words):
            f.write('"%s"\n' % w.replace("\\", "\\\\").replace('"', '\\"'))


if __name__ == "__main__":
    write_dict()
    xml_corpus()
    obj_corpus()
    ply_corpus()
    serialized_corpus()
    image_corpus()
    for t in sorted(os.listdir(OUT)):
        d = os.path.join(OUT, t, "corpus")
        files = os.listdir(d)
        size = sum(os.path.getsize(os.path.join(d, f)) for f in files)
        print(f"{t}: {len(files)} files, {size} bytes")
