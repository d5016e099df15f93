"""Replay sources: ViSP's file formats, Debian data in a cache, the registry's errors."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError, DependencyError, InvalidInputError
from merlin2_sailor_demos.replay import debian_data
from merlin2_sailor_demos.replay.debian_data import DebianData, locate
from merlin2_sailor_demos.replay.sources import REPLAY_SOURCES, create_source
from merlin2_sailor_demos.replay.visp_files import read_camera_parameters, read_homogeneous_matrix, read_raw_depth

CAMERA_XML = """<?xml version="1.0"?>
<conf>
  <klt><window_size>5</window_size></klt>
  <camera>
    <px>615.1674804688</px>
    <py>615.1675415039</py>
    <u0>312.1889953613</u0>
    <v0>243.4373779297</v0>
  </camera>
</conf>
"""


def write_depth_frame(path, depth: np.ndarray, extra_bytes: bytes = b"") -> None:
    header = np.array([depth.shape[0], depth.shape[1]], dtype="<u4").tobytes()
    path.write_bytes(header + depth.astype("<u2").tobytes() + extra_bytes)


def test_visp_camera_parameters_come_from_the_camera_element(tmp_path) -> None:
    path = tmp_path / "chateau.xml"
    path.write_text(CAMERA_XML)
    camera = read_camera_parameters(path)
    assert (camera.fx, camera.fy, camera.cx, camera.cy) == pytest.approx((615.16748, 615.16754, 312.18900, 243.43738))
    path.write_text(CAMERA_XML.replace("<v0>243.4373779297</v0>", ""))
    with pytest.raises(InvalidInputError, match="lacks <v0>"):
        read_camera_parameters(path)
    path.write_text("<conf><camera>")
    with pytest.raises(InvalidInputError, match="cannot read"):
        read_camera_parameters(path)


def test_a_visp_depth_frame_is_a_size_header_then_little_endian_uint16(tmp_path) -> None:
    depth = np.arange(12, dtype=np.uint16).reshape(3, 4) * 1000
    path = tmp_path / "depth_image_0000.bin"
    write_depth_frame(path, depth)
    read = read_raw_depth(path)
    assert read.dtype == np.uint16 and np.array_equal(read, depth)
    write_depth_frame(path, depth, extra_bytes=b"\x00")
    with pytest.raises(InvalidInputError, match="says 4x3 depth pixels"):
        read_raw_depth(path)


def test_a_printed_homogeneous_matrix_is_read_and_made_a_proper_rotation(tmp_path) -> None:
    path = tmp_path / "depth_M_color.txt"
    path.write_text(
        "0.9999922514  -0.003901827615  -0.000573842437  -0.02470519207\n"
        "0.003898504889  0.9999762774  -0.005681734998  0.0006583171198\n"
        "0.0005959979608  0.005679453723  0.9999836683  -0.003773850389\n"
        "0  0  0  1\n"
    )
    pose = read_homogeneous_matrix(path)
    assert pose.translation == pytest.approx([-0.02470519207, 0.0006583171198, -0.003773850389])
    assert pose.rotation[0, 1] == pytest.approx(-0.0039018, abs=1e-6)
    path.write_text("1 0 0\n0 1 0\n0 0 1\n")
    with pytest.raises(InvalidInputError, match="not a 4x4"):
        read_homogeneous_matrix(path)


def test_data_already_in_the_cache_is_used_without_fetching(tmp_path, monkeypatch) -> None:
    data = DebianData("some-data", "usr/share/some-data/thing.txt", "a test")
    monkeypatch.setattr(DebianData, "installed_path", property(lambda self: tmp_path / "not-installed"))
    (tmp_path / "cache" / "usr/share/some-data").mkdir(parents=True)
    (tmp_path / "cache" / data.member).write_text("hello")
    assert locate(data, tmp_path / "cache", fetch=False) == tmp_path / "cache" / data.member
    monkeypatch.setenv("SAILOR_DATA_CACHE", str(tmp_path / "cache"))
    assert locate(data) == tmp_path / "cache" / data.member


def test_missing_data_says_what_to_install(tmp_path, monkeypatch) -> None:
    data = DebianData("visp-images-data", "usr/share/visp-images-data/x", "the 'sr300' replay")
    monkeypatch.setattr(DebianData, "installed_path", property(lambda self: tmp_path / "not-installed"))
    with pytest.raises(DependencyError, match="sudo apt-get install visp-images-data"):
        locate(data, tmp_path / "cache", fetch=False)
    monkeypatch.setattr(debian_data.shutil, "which", lambda tool: None)
    with pytest.raises(DependencyError, match="apt-get is not available here"):
        locate(data, tmp_path / "cache")


def test_only_the_wanted_part_of_a_package_is_unpacked_into_the_cache(tmp_path) -> None:
    if shutil.which("dpkg-deb") is None:
        pytest.skip("dpkg-deb is not installed (not Debian or Ubuntu): the unpacking step cannot run here")
    tree = tmp_path / "tree"
    (tree / "DEBIAN").mkdir(parents=True)
    (tree / "DEBIAN" / "control").write_text(
        "Package: tiny-data\nVersion: 1.0\nArchitecture: all\nMaintainer: t <t@example.org>\nDescription: test\n"
    )
    (tree / "usr/share/tiny-data/wanted").mkdir(parents=True)
    (tree / "usr/share/tiny-data/wanted/a.txt").write_text("a")
    (tree / "usr/share/tiny-data/other.txt").write_text("b")
    archive = tmp_path / "tiny-data_1.0_all.deb"
    subprocess.run(["dpkg-deb", "--build", "--root-owner-group", str(tree), str(archive)], check=True,
                   capture_output=True)
    cache = tmp_path / "cache"
    data = DebianData("tiny-data", "usr/share/tiny-data/wanted", "a test")
    debian_data._unpack(archive, data, cache)
    assert (cache / "usr/share/tiny-data/wanted/a.txt").read_text() == "a"
    assert not (cache / "usr/share/tiny-data/other.txt").exists()
    assert [path.name for path in cache.iterdir()] == ["usr"]  # no scratch folder left behind
    with pytest.raises(DependencyError, match="not in the package"):
        debian_data._unpack(archive, DebianData("tiny-data", "usr/share/absent", "a test"), cache)


def test_sources_are_chosen_by_name_and_refuse_options_they_lack(tmp_path) -> None:
    assert set(REPLAY_SOURCES) == {"motorcycle", "sr300", "vtest", "bag"}
    with pytest.raises(ConfigurationError, match="choose one of motorcycle, sr300, vtest"):
        create_source("kitchen")
    with pytest.raises(ConfigurationError, match="no option camera_pitch"):
        create_source("motorcycle", {"camera_pitch": 30.0})
    with pytest.raises(ConfigurationError, match="not ViSP's castel folder"):
        create_source("sr300", {"data": str(tmp_path)})
    with pytest.raises(ConfigurationError, match="is not a file"):
        create_source("vtest", {"data": str(tmp_path / "vtest.avi")})
    with pytest.raises(ConfigurationError, match="pitch"):
        create_source("vtest", {"camera_pitch": 120.0})
