"""OpenSim 4.6 as an optional peer: its inverse-dynamics and static-optimization tools on the
same model and trial, for side-by-side comparison (scenes and ``benchmarks/``).

mbsuite never needs OpenSim: :func:`available` says whether ``import opensim`` works
(``pip install 'mbsuite[peers]'``), and every function here is called only then.  OpenSim's
tools write ``.sto`` files into a scratch folder; they are read back with
:func:`biomech.storage.read_storage` (so the same units and names as ours).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

__all__ = ["available", "version", "run_inverse_dynamics", "run_static_optimization"]


def available() -> bool:
    """True when OpenSim's Python package can be imported."""
    try:
        import opensim  # noqa: F401
    except Exception:
        return False
    return True


def version() -> str:
    import opensim

    return opensim.GetVersionAndDate()


def run_inverse_dynamics(model_file, motion_file, external_loads_file, t0, t1, cutoff=6.0, out_dir=None):
    """OpenSim's InverseDynamicsTool (muscles excluded, coordinates low-passed at ``cutoff``).

    Returns (DataFrame of generalized forces with ``time`` first, wall time [s] of OpenSim's
    own work: loading the model, then ``run()`` (reading the motion and the loads, filtering,
    inverse dynamics, writing the results); reading the results back into Python is not timed).
    """
    import opensim as osim

    from .storage import read_storage

    out = Path(out_dir or tempfile.mkdtemp(prefix="mbsuite-opensim-id-"))
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    model = osim.Model(str(model_file))
    model.initSystem()
    tool = osim.InverseDynamicsTool()
    tool.setModel(model)
    tool.setCoordinatesFileName(str(motion_file))
    tool.setLowpassCutoffFrequency(float(cutoff) if cutoff else -1.0)
    tool.setStartTime(float(t0))
    tool.setEndTime(float(t1))
    tool.setExternalLoadsFileName(str(external_loads_file))
    excluded = osim.ArrayStr()
    excluded.append("Muscles")
    tool.setExcludedForces(excluded)
    tool.setResultsDir(str(out))
    tool.setOutputGenForceFileName("inverse_dynamics.sto")
    if not tool.run():
        raise RuntimeError(f"OpenSim's InverseDynamicsTool failed on {motion_file}")
    wall = time.perf_counter() - start
    return read_storage(out / "inverse_dynamics.sto", convert_angles=False), wall


def run_static_optimization(model_file, motion_file, external_loads_file, actuators_file, t0, t1,
                            cutoff=6.0, exponent=2, out_dir=None):
    """OpenSim's StaticOptimization analysis (AnalyzeTool), Σ activation^exponent, with the
    reserve actuators of ``actuators_file`` appended to the model's forces.

    Returns (activations DataFrame, forces DataFrame, wall time [s] of OpenSim's own work: loading
    the tool with its model from the setup file, then ``run()``; writing the setup file and reading
    the results back into Python are not timed).
    """
    import opensim as osim

    from .storage import read_storage

    out = Path(out_dir or tempfile.mkdtemp(prefix="mbsuite-opensim-so-"))
    out.mkdir(parents=True, exist_ok=True)
    # an AnalyzeTool configured from Python must be written to its setup file and read back
    # before it runs (otherwise: "a storage object containing the time histories of states was
    # not specified")
    tool = osim.AnalyzeTool()
    tool.setName("so")
    tool.setModelFilename(str(Path(model_file).resolve()))
    files = osim.ArrayStr()
    files.append(str(Path(actuators_file).resolve()))
    tool.setForceSetFiles(files)
    tool.setReplaceForceSet(False)
    tool.setCoordinatesFileName(str(Path(motion_file).resolve()))
    tool.setLowpassCutoffFrequency(float(cutoff) if cutoff else -1.0)
    tool.setInitialTime(float(t0))
    tool.setFinalTime(float(t1))
    tool.setExternalLoadsFileName(str(Path(external_loads_file).resolve()))
    tool.setResultsDir(str(out))
    so = osim.StaticOptimization()
    so.setStartTime(float(t0))
    so.setEndTime(float(t1))
    so.setActivationExponent(float(exponent))
    so.setUseMusclePhysiology(True)
    tool.updAnalysisSet().cloneAndAppend(so)
    setup = out / "so_setup.xml"
    tool.printToXML(str(setup))
    start = time.perf_counter()
    tool = osim.AnalyzeTool(str(setup))
    ok = tool.run()
    wall = time.perf_counter() - start
    if not ok:
        raise RuntimeError(f"OpenSim's static optimization failed on {motion_file}")
    act = read_storage(out / "so_StaticOptimization_activation.sto", convert_angles=False)
    frc = read_storage(out / "so_StaticOptimization_force.sto", convert_angles=False)
    return act, frc, wall
