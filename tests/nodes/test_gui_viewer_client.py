"""The GUI's client of the Viewer (gui.ros.viewer.ViewerClient) against a live Viewer: the
camera read, fixed and given back to the Viewer's fitting, a snapshot written, a refusal and an
absent Viewer raised as ViewerError with the service's path."""
from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.forked


def test_the_viewer_client_moves_the_camera_saves_a_snapshot_and_reports_refusals(
        ros_master, tmp_path):
    from gui.errors import ViewerError
    from gui.ros.viewer import ViewerClient
    ros_master.rosrun("Viewer", "viewer", "_width:=320", "_height:=240",
                      f"_snapshot_dir:={tmp_path / 'snaps'}")
    ros_master.wait_for_service("/viewer/set_camera")
    viewer = ViewerClient(timeout=30)
    try:
        assert (viewer.camera().width, viewer.camera().height) == (320, 240)
        fixed = viewer.set_camera(eye=(3.0, 0.0, 1.0), target=(0.0, 0.0, 0.5))
        assert fixed.refusal == ""
        assert fixed.camera.eye == pytest.approx((3.0, 0.0, 1.0))
        assert viewer.camera().target == pytest.approx((0.0, 0.0, 0.5))
        refused = viewer.set_camera(eye=(1.0, 1.0, 1.0), target=(1.0, 1.0, 1.0))
        assert refused.refusal                       # eye == target: the camera stays
        assert refused.camera.eye == pytest.approx((3.0, 0.0, 1.0))
        assert viewer.set_camera(fit_scene=True).refusal == ""

        path = viewer.save_snapshot("client.png")
        assert os.path.isfile(path) and path.startswith(str(tmp_path / "snaps"))
        with pytest.raises(ViewerError, match="^/viewer/save_snapshot: "):
            viewer.save_snapshot("../outside.png")
    finally:
        viewer.close()


def test_no_viewer_is_a_viewer_error_naming_the_namespace(ros_master):
    from gui.errors import ViewerError
    from gui.ros.viewer import ViewerClient
    with pytest.raises(ViewerError, match=r"^/nowhere: no Viewer answering after 0.5 s"):
        ViewerClient("/nowhere", timeout=0.5)
