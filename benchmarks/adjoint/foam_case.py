"""The OpenFOAM side of the adjoint example: the case dictionaries (laminar simpleFoam and
adjointOptimisationFoam of OpenFOAM v1912), ASCII polyMesh and field readers, and the value
of the objective.

The objective is OpenFOAM's PtLosses on the inlet and outlet patches,
    J = - sum over the faces f of inlet and outlet of (U_f . S_f) (p_f + |U_f|^2 / 2),
the net flux of total pressure (kinematic, m^5/s^3 for SI lengths) that the duct loses. The
adjoint solver prints it; the primal runs compute the same sum with two surfaceFieldValue
function objects (weightedAreaIntegrate with the vector weight U is sum (U_f . S_f) x field)
of the total pressure of the `pressure` function object."""
import os
import re

import numpy as np

HEADER = "FoamFile { version 2.0; format ascii; class %s; object %s; }\n"
WALLS = ("bump", "walls")

CONTROL = """application simpleFoam; startFrom latestTime; startTime 0; stopAt endTime;
endTime %(iters)d; deltaT 1; writeControl timeStep; writeInterval %(iters)d; purgeWrite 1;
writeFormat ascii; writePrecision 17; writeCompression off; timeFormat general;
timePrecision 6; runTimeModifiable false;
functions {
  ptot { type pressure; libs ("libfieldFunctionObjects.so"); mode total; rho rhoInf;
         rhoInf 1; pRef 0; result ptot; log false; writeControl writeTime; }
  inletPt { type surfaceFieldValue; libs ("libfieldFunctionObjects.so"); regionType patch;
            name inlet; operation weightedAreaIntegrate; weightField U; fields (ptot);
            writeFields false; log false; }
  outletPt { type surfaceFieldValue; libs ("libfieldFunctionObjects.so"); regionType patch;
             name outlet; operation weightedAreaIntegrate; weightField U; fields (ptot);
             writeFields false; log false; }
}
"""

# linearUpwind convection; SIMPLE with the relaxation of OpenFOAM's sbend laminar
# sensitivity-map tutorial (adjointOptimisationFoam's primal has no SIMPLEC)
SCHEMES = """ddtSchemes { default steadyState; }
gradSchemes { default Gauss linear; }
divSchemes { default Gauss linear; div(phi,U) bounded Gauss linearUpwind grad(U);
  div(-phi,Ua) bounded Gauss linearUpwind grad(Ua);
  div((nuEff*dev2(T(grad(U))))) Gauss linear; div((nuEff*dev(grad(U).T()))) Gauss linear;
  div((nuEff*dev(grad(Ua).T()))) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
"""

SOLUTION = """SIMPLE { nNonOrthogonalCorrectors 0; residualControl { p %(tol)g; U %(tol)g; } }
solvers {
  "(p|pa)" { solver GAMG; smoother GaussSeidel; tolerance 1e-14; relTol 0.01; }
  "(ma)" { solver PCG; preconditioner DIC; tolerance 1e-14; relTol 0.01; }
  "(U|Ua)" { solver PBiCGStab; preconditioner DILU; tolerance 1e-14; relTol 0.1; }
}
relaxationFactors { fields { p 0.5; pa 0.5; } equations { U 0.7; Ua 0.7; } }
"""

# surfacePoints with includeSurfaceArea: the point field pointSensVec<solver>ESI is dJ/dx of
# each boundary point (not divided by the area around the point); writeAllSurfaceFiles
# writes it (v1912 writes only the normal component otherwise).
OPTIMISATION = """optimisationManager singleRun;
primalSolvers { p1 { active true; type incompressible; solver simple;
  solutionControls { nIters %(iters)d; residualControl { "p.*" %(tol)g; "U.*" %(tol)g; } } } }
adjointManagers { am1 { primalSolver p1; adjointSolvers { as1 {
  active true; type incompressible; solver adjointSimple;
  objectives { type incompressible;
    objectiveNames { losses { weight 1; type PtLosses; patches (inlet outlet); } } }
  ATCModel { ATCModel standard; }
  solutionControls { nIters %(iters)d; residualControl { "pa.*" %(tol)g; "Ua.*" %(tol)g; } }
} } } }
optimisation { sensitivities { type surfacePoints; patches (bump walls);
  includeSurfaceArea true; writeAllSurfaceFiles true; } }
"""

FIELDS = {
    ("volVectorField", "U"): """dimensions [0 1 -1 0 0 0 0]; internalField uniform (%(u)g 0 0);
boundaryField { inlet { type fixedValue; value uniform (%(u)g 0 0); }
  outlet { type zeroGradient; } "(bump|walls)" { type noSlip; } }
""",
    ("volScalarField", "p"): """dimensions [0 2 -2 0 0 0 0]; internalField uniform 0;
boundaryField { inlet { type zeroGradient; } outlet { type fixedValue; value uniform 0; }
  "(bump|walls)" { type zeroGradient; } }
""",
    ("volVectorField", "Ua"): """dimensions [0 1 -1 0 0 0 0]; internalField uniform (0 0 0);
boundaryField { inlet { type adjointInletVelocity; value uniform (0 0 0); }
  outlet { type adjointOutletVelocity; value uniform (0 0 0); }
  "(bump|walls)" { type adjointWallVelocity; value uniform (0 0 0); } }
""",
    ("volScalarField", "pa"): """dimensions [0 2 -2 0 0 0 0]; internalField uniform 0;
boundaryField { inlet { type zeroGradient; }
  outlet { type adjointOutletPressure; value uniform 0; } "(bump|walls)" { type zeroGradient; } }
""",
    ("volVectorField", "ma"): """dimensions [0 3 -3 0 0 0 0]; internalField uniform (0 0 0);
boundaryField { ".*" { type fixedValue; value uniform (0 0 0); } }
""",
}


def write_dicts(case: str, nu: float, u_in: float, iters: int, tol: float) -> None:
    """Writes system/, constant/ (not polyMesh) and 0/ of a laminar duct case."""
    files = {
        ("system", "controlDict"): CONTROL % {"iters": iters},
        ("system", "fvSchemes"): SCHEMES,
        ("system", "fvSolution"): SOLUTION % {"tol": tol},
        ("system", "optimisationDict"): OPTIMISATION % {"iters": iters, "tol": tol},
        ("constant", "transportProperties"): "transportModel Newtonian; nu %r;\n" % nu,
        ("constant", "turbulenceProperties"): "simulationType laminar;\n",
        ("constant", "adjointRASProperties"):
            "adjointRASModel adjointLaminar; adjointTurbulence on; printCoeffs off;\n",
    }
    for (cls, name), text in FIELDS.items():
        files[("0", name)] = (cls, text % {"u": u_in})
    for (d, name), text in files.items():
        cls = "dictionary"
        if isinstance(text, tuple):
            cls, text = text
        os.makedirs(os.path.join(case, d), exist_ok=True)
        with open(os.path.join(case, d, name), "w") as f:
            f.write(HEADER % (cls, name) + text)


def set_wall_patches(case: str) -> None:
    """gmshToFoam makes every patch a `patch`: bump and walls become `wall` (the adjoint wall
    conditions and the sensitivities' wall-gradient correction need wall patches)."""
    path = os.path.join(case, "constant", "polyMesh", "boundary")
    with open(path) as f:
        s = f.read()
    for name in WALLS:
        s, n = re.subn(r"(\b%s\s*\{\s*type\s+)patch;(\s*physicalType\s+patch;)?" % name,
                       r"\1wall;", s)
        if n != 1:
            raise SystemExit("foam_case: no patch %s in %s" % (name, path))
    with open(path, "w") as f:
        f.write(s)


def _list_body(text: str, start: int = 0):
    """(count, the text between the list's brackets) of the first ASCII list at/after start."""
    m = re.compile(r"(\d+)\s*\(").search(text, start)
    if not m:
        raise ValueError("no list")
    n = int(m.group(1))
    depth, i = 1, m.end()
    while depth:
        c = text[i]
        depth += c == "("
        depth -= c == ")"
        i += 1
    return n, text[m.end():i - 1]


def _vectors(n: int, body: str) -> np.ndarray:
    """The n vectors "(x y z)" of a list body as an (n, 3) array."""
    v = np.array(body.replace("(", " ").replace(")", " ").split(), dtype=float).reshape(-1, 3)
    if v.shape[0] != n:
        raise ValueError("expected %d vectors, read %d" % (n, v.shape[0]))
    return v


def read_points(case: str) -> np.ndarray:
    """The points of an ASCII polyMesh, in file order (the labels faces use)."""
    with open(os.path.join(case, "constant", "polyMesh", "points")) as f:
        t = f.read()
    return _vectors(*_list_body(t, t.index("}")))


def read_point_vectors(path: str) -> np.ndarray:
    """internalField of an ASCII pointVectorField (one vector per mesh point)."""
    with open(path) as f:
        t = f.read()
    i = t.index("internalField")
    if re.match(r"internalField\s+uniform", t[i:]):
        raise ValueError("%s: uniform internalField" % path)
    return _vectors(*_list_body(t, i))


def patch_points(case: str, names) -> np.ndarray:
    """Sorted point labels of the faces of the named patches."""
    mesh = os.path.join(case, "constant", "polyMesh")
    with open(os.path.join(mesh, "boundary")) as f:
        b = f.read()
    with open(os.path.join(mesh, "faces")) as f:
        t = f.read()
    n, body = _list_body(t, t.index("}"))
    faces = re.findall(r"\d+\s*\(([^)]*)\)", body)
    if len(faces) != n:
        raise ValueError("faces: expected %d, read %d" % (n, len(faces)))
    pts = set()
    for name in names:
        m = re.search(r"\b%s\s*\{[^}]*?nFaces\s+(\d+);[^}]*?startFace\s+(\d+);" % name, b)
        if not m:
            raise ValueError("no patch %s" % name)
        nf, start = int(m.group(1)), int(m.group(2))
        for face in faces[start:start + nf]:
            pts.update(int(x) for x in face.split())
    return np.array(sorted(pts), dtype=np.int64)


def last_row(path: str) -> list:
    """The numbers of the last row of an OpenFOAM .dat file."""
    with open(path) as f:
        rows = [r.split() for r in f if r.strip() and not r.startswith("#")]
    return [float(x) for x in rows[-1]]


def primal_objective(case: str) -> float:
    """J of a finished simpleFoam run from its function objects' last row."""
    pp = os.path.join(case, "postProcessing")
    vals = {}
    for name in ("inletPt", "outletPt"):
        d = os.path.join(pp, name)
        time_dir = sorted(os.listdir(d), key=float)[-1]
        vals[name] = last_row(os.path.join(d, time_dir, "surfaceFieldValue.dat"))[1]
    return -(vals["inletPt"] + vals["outletPt"])


def final_residuals(log: str, fields) -> tuple:
    """The iteration count and each field's last initial residual in a solver log."""
    with open(log) as f:
        t = f.read()
    res = {}
    for fld in fields:
        m = re.findall(r"Solving for %s, Initial residual = ([-+.\deE]+)" % fld, t)
        res[fld] = float(m[-1]) if m else float("nan")
    its = re.findall(r"converged in (\d+) iterations", t)
    return [int(x) for x in its], res
