"""scans/manifest.toml and the loader: every real scan of ../shared/scans is listed with units,
frame, licence and source (../shared/scans/SOURCES.md), is read in place and comes back in
metres."""
import hashlib

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.scans import load_manifest, load_scan, scan_entry, shared_scans_dir
from graspdef.scans.manifest import SHARED_SCANS_ENV, load_manifest as _load


@pytest.fixture(scope="module")
def manifest():
    return load_manifest()


def _git_blob(path):
    data = path.read_bytes()
    return hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest()


def test_every_entry_has_units_frame_licence_source_and_exists(manifest):
    assert len(manifest.real) == 32  # 30 YCB nontextured.ply + the two LINEMOD duck files
    shared = shared_scans_dir()
    for entry in manifest.real.values():
        assert entry.units in ("m", "mm") and entry.frame and entry.licence and entry.source
        path = entry.file()
        assert path.is_file(), path
        assert shared in path.parents  # read in place, not from the repository
        assert path.stat().st_size == entry.extra["bytes"]


def test_every_shared_scan_folder_is_listed(manifest):
    listed = {entry.path.split("/")[0] for entry in manifest.real.values()}
    folders = {p.name for p in shared_scans_dir().iterdir() if p.is_dir()}
    assert folders == listed


@pytest.mark.parametrize("sid", ["ycb_056_tennis_ball", "linemod_lmo_obj09_duck"])
def test_files_are_the_upstream_bytes(manifest, sid):
    """The blob prefixes of SOURCES.md (git hash-object of the upstream file)."""
    entry = manifest.real[sid]
    assert _git_blob(entry.file()).startswith(entry.extra["blob"])


def test_loader_returns_metres(manifest):
    """SOURCES.md: the tennis ball is 0.0670 x 0.0670 x 0.0665 m; the duck 104.43 x 77.41 x
    85.70 mm (stored in mm, returned in m)."""
    ball = load_scan("ycb_056_tennis_ball", manifest)
    np.testing.assert_allclose(np.ptp(ball.vertices, axis=0), [0.0670, 0.0670, 0.0665], atol=6e-5)
    assert (ball.n_vertices, ball.n_faces) == (8194, 16384)
    duck = load_scan("linemod_lmo_obj09_duck", manifest)
    np.testing.assert_allclose(np.ptp(duck.vertices, axis=0), [0.10443, 0.07741, 0.08570],
                               atol=6e-6)


def test_shared_folder_override_by_environment(monkeypatch, tmp_path, manifest):
    (tmp_path / "ycb_056_tennis_ball").mkdir()
    (tmp_path / "ycb_056_tennis_ball" / "nontextured.ply").symlink_to(
        scan_entry("ycb_056_tennis_ball", manifest).file())
    monkeypatch.setenv(SHARED_SCANS_ENV, str(tmp_path))
    assert shared_scans_dir() == tmp_path.resolve()
    assert load_scan("ycb_056_tennis_ball", manifest).n_faces == 16384
    monkeypatch.setenv(SHARED_SCANS_ENV, str(tmp_path / "missing"))
    with pytest.raises(ProblemError, match="shared scans folder not found"):
        load_scan("ycb_056_tennis_ball", manifest)


def test_unknown_id_and_bad_manifests(tmp_path, manifest):
    with pytest.raises(ProblemError, match="unknown scan id 'ycb_999'"):
        scan_entry("ycb_999", manifest)
    bad = tmp_path / "m.toml"
    bad.write_text('[real.x]\npath = "x.ply"\nunits = "furlong"\nframe = "f"\nlicence = "l"\n'
                   'source = "s"\n')
    with pytest.raises(ProblemError, match=r"m.toml: \[real.x\] units: unknown length unit 'furlong'; "
                                           r"accepted: m, mm, cm, um, in"):
        _load(bad)
    bad.write_text('[real.x]\npath = "x.ply"\nunits = "m"\n')
    with pytest.raises(ProblemError, match=r"missing keys 'frame', 'licence', 'source' in \[real.x\]"):
        _load(bad)


@pytest.mark.parametrize("text, message", [
    ('[real.x]\npath = "x.ply"\nunits = "m"\nframe = "f"\nlicence = "l"\nsource = "s"\nblobb = "0"\n',
     r"unknown key 'blobb' in \[real.x\] \(did you mean 'blob'\?\); accepted: blob, "),
    ('[real.x]\ndefaults = "ycbb"\npath = "x.ply"\n[defaults.ycb]\nunits = "m"\n',
     r"\[real.x\] unknown defaults 'ycbb' \(did you mean 'ycb'\?\)"),
    ('[generated.g]\nsource = "x"\nsigma = 0.1\n', r"unknown key 'sigma' in \[generated.g\] \(did you mean 'sigma_mm'\?\)"),
    ('[real.x]\npath = "x.ply\n', r"m.toml: line 2, column \d+: not valid TOML"),
])
def test_manifest_errors_name_the_table_and_key(tmp_path, text, message):
    bad = tmp_path / "m.toml"
    bad.write_text(text)
    with pytest.raises(ProblemError, match=message):
        _load(bad)


def test_generated_recipes_name_known_sources(manifest):
    assert manifest.generated_dir.parts[-2:] == ("out", "scans")
    assert manifest.generated
    for recipe in manifest.generated.values():
        assert recipe["source"] in manifest.real or recipe["source"].startswith("ellipsoid:")
        assert recipe["sigma_mm"] == 0.127
