"""The attributes of a render's file are the same whoever wrote it: `facet render`, facet.write of
a rendered Image, `facet merge` and facet.merge (one library function builds them)."""

import shutil
import subprocess

import pytest

import facet

SMALL = dict(res=24, spp=2, max_depth=2)
# Attributes whose values the CLI's and Python's renders of the same scene and seed share.
AGREE = ["facet:scene_hash", "facet:seed", "facet:spp", "facet:spp_total", "facet:sample_offset",
         "facet:pass_index", "facet:pass_count", "facet:crop", "facet:film_size", "facet:scene",
         "facet:mode", "samplesPerPixel", "worldToCamera", "worldToNDC"]


def attributes(path):
    """Every attribute of an image file, as OpenImageIO's iinfo prints it: {name: text}."""
    out = subprocess.run(["iinfo", "-v", str(path)], check=True, capture_output=True,
                         text=True).stdout
    attrs = {}
    for line in out.splitlines()[1:]:
        name, sep, value = line.strip().partition(": ")
        if sep:
            attrs[name] = value
    return attrs


@pytest.fixture
def iinfo():
    if shutil.which("iinfo") is None:
        pytest.skip("iinfo (openimageio-tools) is not installed: cannot read the attributes")


def cli_render(facet_cli, cli_env, cornell, out, *args):
    cmd = [str(facet_cli), "render", str(cornell), "-q", "--seed", "3", "-o", str(out), *args]
    subprocess.run(cmd + [f"-D{k}={v}" for k, v in SMALL.items()], check=True, env=cli_env)


def test_cli_python_and_merge_write_the_same_attributes(iinfo, cornell, facet_cli, cli_env,
                                                        tmp_path):
    cli = tmp_path / "cli.exr"
    cli_render(facet_cli, cli_env, cornell, cli)
    crops = [(0, 0, 24, 10), (0, 10, 24, 24)]
    for i, c in enumerate(crops):
        cli_render(facet_cli, cli_env, cornell, tmp_path / f"crop{i}.exr", "--crop",
                   *[str(v) for v in c])
    merged = tmp_path / "merged.exr"
    subprocess.run([str(facet_cli), "merge", "-q", str(tmp_path / "crop0.exr"),
                    str(tmp_path / "crop1.exr"), "-o", str(merged)], check=True, env=cli_env)

    scene = facet.load_file(cornell, **SMALL)
    image = facet.render(scene, seed=3, progress=False)
    py = tmp_path / "py.exr"
    facet.write(image, py)
    py_merged = tmp_path / "py_merged.exr"
    facet.merge([facet.render(scene, seed=3, crop=c, progress=False) for c in crops], py_merged)
    mixed = tmp_path / "mixed.exr"
    facet.merge([str(tmp_path / "crop0.exr"),
                 facet.render(scene, seed=3, crop=crops[1], progress=False)], mixed)

    a = attributes(cli)
    for name in ["samplesPerPixel", "renderTimeSeconds", "worldToCamera", "worldToNDC",
                 "facet:render_time", "facet:scene", "facet:scene_hash"]:
        assert name in a, name
    for path in [py, merged, py_merged, mixed]:
        b = attributes(path)
        extra = {"facet:merged_parts"} if "merged" in path.name or path == mixed else set()
        assert set(b) == set(a) | extra, path.name
        for name in AGREE:
            assert b[name] == a[name], (path.name, name)
    assert attributes(merged)["facet:merged_parts"] == '"2"'  # iinfo quotes strings

    # The Image's metadata holds the same, typed as the file has it.
    assert image.metadata["samplesPerPixel"] == 2
    assert isinstance(image.metadata["renderTimeSeconds"], float)
    assert len(image.metadata["worldToCamera"]) == 4
    assert image.metadata["facet:spp"] == "2"
