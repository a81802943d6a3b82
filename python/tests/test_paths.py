"""Path arguments: a NUL character is refused (it cut the path short on the C++ side), and a scene
file that is not a regular file is an error, not a read that blocks."""
import os
import subprocess
import sys

import numpy as np
import pytest

import facet


def test_nul_in_a_path_is_a_value_error(tmp_path):
    scene = tmp_path / "scene.xml"
    scene.write_text('<scene version="3.0.0"/>\n')
    # Without the check, "scene.xml\0junk" loaded scene.xml.
    with pytest.raises(ValueError, match="NUL"):
        facet.load_file(str(scene) + "\0junk")
    with pytest.raises(ValueError, match="NUL"):
        facet.load_file(scene, search_path=[str(tmp_path) + "\0x"])
    with pytest.raises(ValueError, match="NUL"):
        facet.load_string('<scene version="3.0.0"/>', search_path=["a\0b"])
    with pytest.raises(ValueError, match="NUL"):
        facet.read(str(tmp_path / "image.exr") + "\0.png")
    with pytest.raises(ValueError, match="NUL"):
        facet.write(np.zeros((2, 2, 3), dtype=np.float32), str(tmp_path / "out.exr") + "\0.png")
    with pytest.raises(ValueError, match="NUL"):
        facet.merge([str(tmp_path / "a.exr") + "\0", str(tmp_path / "b.exr")])
    with pytest.raises(ValueError, match="NUL"):
        facet.add_plugin_dir(str(tmp_path) + "\0plugins")


def test_a_fifo_is_refused_not_read(tmp_path):
    fifo = tmp_path / "scene.xml"
    os.mkfifo(fifo)
    code = ("import facet, sys\n"
            "try:\n"
            f"    facet.load_file({str(fifo)!r})\n"
            "except facet.Error as e:\n"
            "    print(e)\n"
            "    sys.exit(0 if 'FIFO' in str(e) else 3)\n"
            "sys.exit(4)\n")
    # In a child process: the read blocked forever.
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
