"""The viser server without a browser: clean start and stop, bad input, the load-path slider and
the live re-solves (checked on the server side)."""
from __future__ import annotations

import socket
import threading
import time

import numpy as np
import pytest

import viser  # noqa: F401  (the viewer extra is part of make test)

from graspdef.cli import main as graspdef_main  # noqa: E402
from graspdef.runs.read import RunFolderError  # noqa: E402
from graspdef.viewer.server import Viewer, ViewerError  # noqa: E402


def view_main(argv):
    return graspdef_main(["view", *argv])


def port_is_free(port: int, host: str = "127.0.0.1") -> bool:
    s = socket.socket()
    try:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.bind((host, port))
        return True
    except OSError:
        return False
    finally:
        s.close()


def _threads() -> set:
    return {t for t in threading.enumerate() if t.is_alive()}


def test_start_stop_clean(plate_run, cantilever_run):
    before = _threads()
    with Viewer([plate_run, cantilever_run], port=0) as v:
        port = v.port
        assert v.url == f"http://127.0.0.1:{port}" and not port_is_free(port)
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            pass
        assert v.wait_ready(120)
        assert len(_threads() - before) >= 2                   # viser's server thread and our worker
    deadline = time.time() + 10
    while (_threads() - before) and time.time() < deadline:
        time.sleep(0.05)
    assert not (_threads() - before), f"leaked threads: {_threads() - before}"
    assert port_is_free(port)
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), timeout=2).close()
    v.stop()                                                   # a second stop is harmless


def test_same_port_again_after_stop(plate_run):
    with Viewer(plate_run, port=0, live=False) as v:
        port = v.port
    with Viewer(plate_run, port=port, live=False) as v2:
        assert v2.port == port


def test_port_in_use(plate_run, capsys):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    s.listen()
    port = s.getsockname()[1]
    before = _threads()
    try:
        with pytest.raises(ViewerError, match=f"port {port} on 127.0.0.1 is in use"):
            Viewer(plate_run, port=port, live=False)
        assert view_main([str(plate_run), "--port", str(port)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("graspdef: error: port") and "in use" in err and err.count("\n") == 1
    finally:
        s.close()
    assert not (_threads() - before)


def test_missing_and_incomplete_folders(tmp_path, capsys):
    with pytest.raises(RunFolderError, match="does not exist"):
        Viewer(tmp_path / "nope", port=0)
    (tmp_path / "half").mkdir()
    (tmp_path / "half" / "result.json").write_text("{}")
    assert view_main([str(tmp_path / "half"), "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert "incomplete: missing deformed.ply, undeformed.ply" in err and err.count("\n") == 1


def test_path_slider_changes_mesh(cantilever_run):
    with Viewer(cantilever_run, port=0, live=False) as v:
        rv = v.views[0]
        k_last = rv.n_path - 1
        assert rv.step == k_last
        final = rv.displayed.copy()
        v.show_path_point(0, 1)
        assert rv.step == 1 and "path point 1" in rv.source
        expected = rv.to_display(rv.run.rest_vertices + rv.run.path_displacements(1))
        np.testing.assert_allclose(rv.displayed, expected, atol=1e-6)
        assert np.abs(rv.displayed - final).max() > 0.05           # display units: object size ~1
        v.show_path_point(0, 0)
        np.testing.assert_allclose(rv.displayed, rv.to_display(rv.run.rest_vertices), atol=1e-6)
        assert "load factor" in rv.chart.content or "<svg" in rv.chart.content
        v.show_path_point(0, k_last)
        v.scale_input.value = 0.0                                  # deformation scale 0: the rest shape
        v._redraw_all()
        np.testing.assert_allclose(rv.displayed, rv.to_display(rv.run.rest_vertices), atol=1e-6)
        v.scale_input.value = 2.0
        v.show_dropdown.value = "both"
        v._redraw_all()
        np.testing.assert_allclose(rv.displayed, rv.to_display(rv.run.rest_vertices + 2 * rv.run.displacements),
                                   atol=1e-5)
        assert rv.mesh_handle.visible and rv.rest_handle.visible
        v.show_dropdown.value = "undeformed"
        v._redraw_all()
        assert not rv.mesh_handle.visible and rv.rest_handle.visible


def test_live_linear_exact_and_fast(plate_run):
    with Viewer(plate_run, port=0) as v:
        assert v.wait_ready(120)
        rv = v.views[0]
        assert rv.live is not None and rv.live_error is None
        u0 = rv.run.displacements
        r = v.set_live(0, 2.0, 1.0)
        assert r.converged and r.seconds < 1.0
        np.testing.assert_allclose(r.displacements, 2 * u0, rtol=1e-6, atol=1e-12 * np.abs(u0).max())
        r = v.set_live(0, 1.0, 4.0)                                # E x 4: a quarter
        np.testing.assert_allclose(r.displacements, u0 / 4, rtol=1e-6, atol=1e-12 * np.abs(u0).max())
        np.testing.assert_allclose(rv.displayed, rv.to_display(rv.run.rest_vertices + u0 / 4), atol=1e-6)
        assert "live" in rv.source and "converged" in rv.live_status.content
        assert "finger force [N]" == rv.force_slider.label and "N/mm²" in rv.modulus_slider.label
        assert rv.modulus_slider.value == pytest.approx(4 * 2000.0)    # E in the run's units, synced
        assert rv.force_slider.value == pytest.approx(2.0)             # the run's 2 N


def test_live_nonlinear_reaches_path_point(cantilever_run):
    with Viewer(cantilever_run, port=0) as v:
        assert v.wait_ready(120)
        rv = v.views[0]
        u, lf, _ = rv.run.path_u
        k = 2
        r = v.set_live(0, lf[k], 1.0)                              # Newton from the final state back
        assert r.converged, r.message
        np.testing.assert_allclose(r.displacements, rv.run.path_displacements(k), atol=1e-6 * np.abs(u).max())
        r2 = v.set_live(0, 1.0, 1.0 / lf[k])                       # E x 1/lf: the same state again
        assert r2.converged
        np.testing.assert_allclose(r2.displacements, rv.run.path_displacements(k), atol=1e-6 * np.abs(u).max())
        r3 = v.set_live(0, 50.0, 1.0)                              # far beyond: may not converge
        if not r3.converged:
            assert "not converged" in rv.live_status.content
            np.testing.assert_allclose(rv.disp, r2.displacements)  # the last converged state stays


@pytest.mark.slow
def test_path_resolved_when_path_u_absent(cantilever_run_no_path, cantilever_run):
    with Viewer(cantilever_run_no_path, port=0) as v:
        assert v.wait_ready(120)
        rv = v.views[0]
        assert rv.run.path_u is not None and rv.path_exact
        from graspdef.runs.read import read_run

        good = read_run(cantilever_run)
        for k in range(rv.n_path):
            np.testing.assert_allclose(rv.run.path_displacements(k), good.path_displacements(k), atol=1e-8)


def test_click_shows_numbers(plate_run):
    with Viewer(plate_run, port=0, live=False) as v:
        rv = v.views[0]
        assert rv.run.contacts is not None and rv.run.scan is not None        # drawn without error
        centre = int(np.argmin(np.linalg.norm(rv.run.rest_vertices[:, :2], axis=1)))
        target = rv.displayed[centre].astype(float)
        text = rv.pick(target + [0, 0, 3.0], (0, 0, -1))                       # straight down onto it
        w = rv.run.displacements[centre] * 1e3
        assert f"picked vertex {centre}" in text and f"{np.linalg.norm(w):.4g} mm" in text
        assert "nearest scan point" in text and "mm" in text and rv.info.content.count("picked") == 1
