"""The mvflow Python module (tools/python/module.cpp), run by CTest through pytest.

A small scene is rendered once by the mvflow program (MVFLOW_BINARY); the module's results are
compared with the program's on the same input, and with analytic cases."""

import os
import subprocess
import threading
import time

import numpy as np
import pytest

import mvflow


@pytest.fixture(scope="session")
def scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("scene")
    subprocess.run([os.environ["MVFLOW_BINARY"], "synth", "--views", "8", "--width", "160", "--height", "120",
                    "--level", "3", "--init-vertices", "200", "-o", str(folder)],
                   check=True, stdout=subprocess.DEVNULL)
    return folder


def tetrahedron():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return vertices, faces


def test_mesh_files_round_trip(tmp_path):
    vertices, faces = tetrahedron()
    mvflow.write_mesh(tmp_path / "t.ply", vertices, faces)
    read_vertices, read_faces = mvflow.read_mesh(tmp_path / "t.ply")
    assert read_vertices.shape == (4, 3) and read_vertices.dtype == np.float64
    np.testing.assert_array_equal(read_vertices, vertices)
    np.testing.assert_array_equal(read_faces, faces)


def test_bad_input_raises_with_the_file_and_line(tmp_path):
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(mvflow.InputError, match=str(bad) + ":"):
        mvflow.read_mesh(bad)
    with pytest.raises(mvflow.IoError):
        mvflow.read_mesh(tmp_path / "absent.ply")
    vertices, faces = tetrahedron()
    with pytest.raises(mvflow.InputError, match=r"faces\[1\]: vertex index 7"):
        mvflow.write_mesh(tmp_path / "x.ply", vertices, np.array([[0, 1, 2], [0, 1, 7]]))
    with pytest.raises(mvflow.InputError, match="N×3"):
        mvflow.write_mesh(tmp_path / "x.ply", vertices[:, :2], faces)
    assert isinstance(mvflow.InputError("x"), ValueError)


def test_evaluate_an_analytic_offset():
    vertices, faces = tetrahedron()
    result = mvflow.evaluate((vertices, faces), (vertices, faces), samples=2000)
    assert result["mean"] == pytest.approx(0.0, abs=1e-12)
    assert result["completeness"] == 1.0
    # The same tetrahedron moved by 0.01 along x: every distance is at most 0.01.
    moved = mvflow.evaluate((vertices + [0.01, 0, 0], faces), (vertices, faces), samples=2000)
    assert 0.0 < moved["mean"] <= 0.01 + 1e-12
    assert moved["hausdorff"] == pytest.approx(0.01, rel=1e-9)


def test_refine_gives_the_programs_bits(scene, tmp_path):
    result = mvflow.refine(scene, max_iterations=6, min_iterations=6, threads=2)
    assert result["iterations"] == 6
    assert result["vertices"].shape[1] == 3 and result["faces"].shape[1] == 3
    assert result["final_sum_g_per_vertex"] < result["initial_sum_g_per_vertex"]
    # Photographs noisier than the reference (0.002) are blurred down to it, so the settled
    # tolerance stays the option's; a clean render is left as it is.
    assert result["image_noise"] > 0.0
    assert (result["denoise_sigma"] > 0.0) == (result["image_noise"] > 0.002)
    assert result["settled_tolerance"] == pytest.approx(0.0025)
    out = tmp_path / "refined.ply"
    subprocess.run([os.environ["MVFLOW_BINARY"], "refine", str(scene), "-o", str(out), "--max-iterations", "6",
                    "--min-iterations", "6", "--threads", "1"], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    program_vertices, program_faces = mvflow.read_mesh(out)
    np.testing.assert_array_equal(result["vertices"], program_vertices)
    np.testing.assert_array_equal(result["faces"], program_faces)
    # The initial mesh as arrays gives the same result as the scene's init.* file.
    init = next(p for p in os.listdir(scene) if p.startswith("init."))
    from_arrays = mvflow.refine(scene, mesh=mvflow.read_mesh(scene / init), max_iterations=6, min_iterations=6)
    np.testing.assert_array_equal(from_arrays["vertices"], result["vertices"])


def test_masks_give_the_programs_bits(tmp_path):
    masked = tmp_path / "masked"
    subprocess.run([os.environ["MVFLOW_BINARY"], "synth", "--views", "8", "--width", "160", "--height", "120",
                    "--level", "3", "--init-vertices", "200", "--masks", "-o", str(masked)],
                   check=True, stdout=subprocess.DEVNULL)
    masks = masked / "masks"
    result = mvflow.refine(masked, masks=masks, max_iterations=6, min_iterations=6)
    plain = mvflow.refine(masked, max_iterations=6, min_iterations=6)
    assert not np.array_equal(result["vertices"], plain["vertices"])  # the rims were fitted
    out = tmp_path / "refined.ply"
    subprocess.run([os.environ["MVFLOW_BINARY"], "refine", str(masked), "--masks", str(masks), "-o", str(out),
                    "--max-iterations", "6", "--min-iterations", "6"], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    np.testing.assert_array_equal(result["vertices"], mvflow.read_mesh(out)[0])
    worker = mvflow.Worker(threads=2)
    job = worker.result(worker.submit(masked, masks=masks, max_iterations=6, min_iterations=6))
    assert job["state"] == "succeeded", job["message"]
    np.testing.assert_array_equal(job["vertices"], result["vertices"])
    with pytest.raises(mvflow.IoError, match="mask folder"):
        mvflow.refine(masked, masks=tmp_path / "none")


def test_refine_options_are_checked(scene):
    with pytest.raises(mvflow.InputError, match=r"--max-view-angle: .*max_angle_degrees = 200 .*\(0, 90\]"):
        mvflow.refine(scene, max_view_angle=200)
    with pytest.raises(mvflow.InputError, match="no-such-option"):
        mvflow.refine(scene, no_such_option=1)
    with pytest.raises(mvflow.IoError):
        mvflow.refine(scene / "missing")


def test_hull_is_closed_and_inside_the_box(scene, capfd):
    vertices, faces = mvflow.hull(scene, resolution=48, vertices=400)
    assert len(vertices) > 100 and faces.shape[1] == 3
    assert capfd.readouterr().out == ""  # a library call prints nothing (the program's report is its own)
    # Closed: every edge is shared by exactly two faces.
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
    with pytest.raises(mvflow.InputError, match="resolution"):
        mvflow.hull(scene, resolution=-1)


def test_worker_submit_progress_result(scene):
    worker = mvflow.Worker(threads=2)
    job = worker.submit(scene, max_iterations=6, min_iterations=6)
    result = worker.result(job)
    assert result["state"] == "succeeded", result["message"]
    assert result["iterations"] == 6
    reference = mvflow.refine(scene, max_iterations=6, min_iterations=6)
    np.testing.assert_array_equal(result["vertices"], reference["vertices"])
    with pytest.raises(mvflow.Error, match="unknown job"):
        worker.progress(job)  # the result was taken: the job is forgotten


def test_cancel_from_another_python_thread(tmp_path):
    large = tmp_path / "large"
    subprocess.run([os.environ["MVFLOW_BINARY"], "synth", "--views", "16", "--width", "320", "--height", "240",
                    "--level", "6", "--init-vertices", "40000", "-o", str(large)], check=True,
                   stdout=subprocess.DEVNULL)
    worker = mvflow.Worker(threads=2)
    job = worker.submit(large, max_iterations=100)

    def cancel_once_iterating():
        while worker.progress(job)["stage"] not in ("iterating", "finishing"):
            time.sleep(0.001)  # progress() only reads: the job runs without the GIL
        worker.cancel(job)

    canceller = threading.Thread(target=cancel_once_iterating)
    canceller.start()
    result = worker.result(job)  # blocks without the GIL, so the other thread runs
    canceller.join()
    assert result["state"] == "cancelled"
    assert result["iterations"] < 100
    # The worker goes on with the next job.
    assert worker.result(worker.submit(large, max_iterations=6, min_iterations=6))["state"] == "succeeded"
