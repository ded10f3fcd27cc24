"""Results files: atomic writes, the schema attributes, complex storage, ParaView files."""

import os

import meshio
import numpy as np
import pytest
import xarray as xr

from fretwear import __version__
from fretwear.io.results import (
    atomic_write,
    check_schema,
    complex_variables,
    label_coordinate,
    read_results,
    to_complex,
    variable,
    write_pvd,
    write_results,
    write_vtu,
)
from fretwear.model import mesh as meshes

ATTRS = dict(title="t", analysis_type="frf", converged=True, case_text="[model]\n",
             case_path="/x/case.toml", analysis={"type": "frf", "n_points": 3})


def small_dataset(scale: float = 1.0) -> xr.Dataset:
    U = scale * np.array([[1.0 + 2.0j, -0.5j], [3.0, 0.0]])
    data = complex_variables("displacement", ("frequency", "axis"), U, "m", "displacement")
    coords = {"frequency": variable("frequency", [10.0, 20.0], "Hz", "excitation frequency"),
              "axis": label_coordinate("axis", ["x", "y"])}
    return xr.Dataset(data, coords=coords)


def leftovers(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_round_trip_with_global_attributes_and_units(tmp_path):
    path = write_results(tmp_path / "results.nc", small_dataset(), **ATTRS)
    ds = read_results(path)
    for key in ("fretwear_version", "title", "analysis_type", "created_utc", "case_file",
                "case_path", "analysis_options", "converged"):
        assert key in ds.attrs
    assert ds.attrs["fretwear_version"] == __version__
    assert ds.attrs["case_file"] == "[model]\n"
    assert ds.attrs["converged"] == 1
    assert ds.attrs["created_utc"].endswith("+00:00")
    for name, var in list(ds.coords.items()) + list(ds.data_vars.items()):
        assert var.attrs["units"] and var.attrs["long_name"], name
    assert ds["displacement_phase"].attrs["units"] == "rad"
    np.testing.assert_allclose(to_complex(ds, "displacement").values,
                               [[1.0 + 2.0j, -0.5j], [3.0, 0.0]], rtol=1e-15, atol=1e-15)
    assert list(ds["axis"].values) == ["x", "y"]
    assert oct(os.stat(path).st_mode & 0o777) == oct(0o666 & ~_umask())


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_schema_refuses_missing_units_and_complex_values():
    ds = small_dataset()
    ds["bad"] = xr.Variable("frequency", [1.0, 2.0], {"long_name": "no units"})
    with pytest.raises(ValueError, match="'bad' has no units"):
        check_schema(ds)
    ds = small_dataset()
    ds["c"] = xr.Variable("frequency", [1j, 2.0], {"units": "m", "long_name": "complex"})
    with pytest.raises(ValueError, match="'c' is complex"):
        check_schema(ds)


def test_failed_write_keeps_the_existing_file_and_leaves_nothing(tmp_path, monkeypatch):
    path = write_results(tmp_path / "results.nc", small_dataset(1.0), **ATTRS)
    before = path.read_bytes()

    def half_write(self, target, *args, **kwargs):
        with open(target, "wb") as f:  # a partial file, then a crash
            f.write(b"\x89HDF\r\n\x1a\npartial")
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", half_write)
    with pytest.raises(OSError, match="disk full"):
        write_results(path, small_dataset(2.0), **ATTRS)
    assert path.read_bytes() == before
    assert leftovers(tmp_path) == []
    np.testing.assert_allclose(read_results(path)["displacement_amplitude"][1, 0], 3.0)


def test_interrupted_write_creates_no_file(tmp_path):
    def interrupted(tmp):
        tmp.write_bytes(b"half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atomic_write(tmp_path / "new.nc", interrupted)
    assert list(tmp_path.iterdir()) == []


def test_read_results_errors(tmp_path):
    from fretwear.errors import InputError

    with pytest.raises(InputError, match="does not exist"):
        read_results(tmp_path / "none.nc")
    (tmp_path / "junk.nc").write_text("not netcdf")
    with pytest.raises(InputError, match="cannot read results file"):
        read_results(tmp_path / "junk.nc")


def test_vtu_and_pvd_for_paraview(tmp_path):
    mesh = meshes.rectangle(1.0, 0.5, 2, 1)
    u = np.arange(12.0).reshape(6, 2)
    path = write_vtu(tmp_path / "modes" / "mode-001.vtu", mesh, {"mode_shape": u},
                     {"frequency_hz": 12.5})
    back = meshio.read(path)
    assert back.points.shape == (6, 3)
    np.testing.assert_array_equal(back.point_data["mode_shape"][:, :2], u)
    np.testing.assert_array_equal(back.point_data["mode_shape"][:, 2], 0.0)
    assert back.cells[0].type == "quad"
    pvd = write_pvd(tmp_path / "modes.pvd", [(1, path)])
    assert 'timestep="1" part="0" file="modes/mode-001.vtu"' in pvd.read_text()


def test_writer_refuses_non_finite_solution_values(tmp_path):
    """A displacement holding NaN or inf (a diverged computation) is refused by the writer
    with one line naming the variable, and no file is written; NaN at a sweep frequency
    whose ``converged`` flag is 0 (a failed point, said as such) is written, and NaN in a
    variable that is not a solution (a residual) is left alone."""
    from fretwear.errors import ConvergenceError

    for bad in (np.nan, np.inf):
        ds = xr.Dataset({"displacement": variable(("tau",), [0.0, bad], "m", "displacement")})
        with pytest.raises(ConvergenceError) as err:
            write_results(tmp_path / "r.nc", ds, title="t", analysis_type="periodic",
                          converged=True)
        assert "'displacement'" in str(err.value) and "\n" not in str(err.value)
        assert not (tmp_path / "r.nc").exists() and not leftovers(tmp_path)
    ds = xr.Dataset({
        "displacement_harmonic_amplitude": variable(("frequency",), [1e-6, np.nan], "m",
                                                    "amplitude"),
        "converged": variable(("frequency",), np.array([1, 0], np.int8), "1", "converged"),
        "residual": variable(("frequency",), [1e-9, np.nan], "1", "residual")})
    write_results(tmp_path / "s.nc", ds, title="t", analysis_type="sweep", converged=False)
    assert (tmp_path / "s.nc").is_file()


def test_writer_accepts_the_padded_axes_of_points():
    """A point of one DOF in a model of two axes has its second axis NaN over the whole
    period (pad_axes): padding, written; a NaN inside the period of a real axis is refused."""
    from fretwear.errors import ConvergenceError
    from fretwear.io.results import check_finite

    disp = np.array([[[1.0, 2.0, 3.0], [np.nan] * 3]])  # (point, axis, tau)
    check_finite(xr.Dataset({"displacement": variable(("point", "axis", "tau"), disp, "m",
                                                      "d")}))
    disp[0, 0, 1] = np.nan
    with pytest.raises(ConvergenceError, match="'displacement'"):
        check_finite(xr.Dataset({"displacement": variable(("point", "axis", "tau"), disp,
                                                          "m", "d")}))
