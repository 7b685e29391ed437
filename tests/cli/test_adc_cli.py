"""`rtsgeom adc`: the file format follows the file name unless --format is given."""

from __future__ import annotations

from rtsgeom.cli import main
from conftest import DEFAULT_SCENE


def test_bin_file_is_a_dca1000_capture_not_numpy(tmp_path, capsys):
    out = tmp_path / "cap0.bin"
    assert main(["adc", str(DEFAULT_SCENE), "--active", "0", "--out", str(out), "--quiet"]) == 0
    assert not out.read_bytes().startswith(b"\x93NUMPY")  # raw int16 I/Q, as TI's tools read
    assert (tmp_path / "cap0.bin.json").is_file()
    npy = tmp_path / "cap0.npy"
    assert main(["adc", str(DEFAULT_SCENE), "--active", "0", "--out", str(npy), "--quiet"]) == 0
    assert npy.read_bytes().startswith(b"\x93NUMPY")
