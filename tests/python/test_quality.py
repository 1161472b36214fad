"""cadmorph.quality against the last line of `cadmorph quality`."""
import subprocess

import numpy as np
import pytest

import cadmorph


def cli_summary(cli, path):
    r = subprocess.run([cli, "quality", str(path)], capture_output=True, text=True, check=True)
    last = r.stdout.strip().splitlines()[-1]
    return dict(kv.split("=") for kv in last.split())


@pytest.mark.parametrize("name", ["msh/box_hole_41.msh", "vtk/meshio_ascii.vtu",
                                  "msh/hybrid_o2_41.msh", "quality/mixed.vtu",
                                  "vtk/vtk_legacy_ascii.vtk"])
def test_quality_equals_cli(cli, data, name):
    q = cadmorph.quality(cadmorph.read_mesh(data / name))
    line = cli_summary(cli, data / name)
    assert "%.6g" % q.min_sj == line["min_scaled_jacobian"]
    assert "%.6g" % q.mean_sj == line["mean_scaled_jacobian"]
    assert q.inverted == int(line["inverted"])
    assert q.cells == int(line["cells"])


def test_per_cell(data):
    mesh = cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu")
    q = cadmorph.quality(mesh)
    assert q.per_cell.shape == (mesh.n_cells,) and q.per_cell.dtype == np.float64
    dims3 = [t in ("hex8", "pyramid5", "wedge6", "tet4") for t in mesh.cell_types]
    assert np.all(np.isnan(q.per_cell[~np.array(dims3)]))
    assert q.min_sj == np.nanmin(q.per_cell)
    assert q.inverted == int(np.sum(q.per_cell <= 0))


def test_quality_sees_moved_points(data):
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    before = cadmorph.quality(mesh)
    mesh.points[:, 0] *= 3.0  # through the view: the library sees the stretch
    after = cadmorph.quality(mesh)
    assert after.min_sj != before.min_sj


def test_quality_rejects_non_mesh():
    with pytest.raises(TypeError, match="cadmorph.Mesh"):
        cadmorph.quality(np.zeros((4, 3)))
