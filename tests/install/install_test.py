#!/usr/bin/python3
"""The installed package as a user sees it: `cmake --install` into a fresh prefix, then the
programs of examples/ configured and built against that prefix three ways - find_package
(cadmorph::cadmorph, shared), find_package (cadmorph::cadmorph_static) and pkg-config - plus
one direct `cc ... $(pkg-config --static --libs cadmorph)` link of libcadmorph.a, and every
build run on the plate-with-a-hole STEP fixtures (tests/data/surface) and gmsh's mesh of it
(fixture surface_meshes).

  install_test.py --cmake CMAKE --build BUILD_DIR --examples SRC_DIR --data TESTS_DATA
                  --mesh HOLE_A_MESH --python PYTHON_SRC_DIR --work DIR

Also checked: the exported symbols of libcadmorph.so are exactly the functions the installed
headers declare (CM_API), `cadmorph --version`, cadmorph.pc and the config version agree, and
the installed program writes a built-in model that it reads back (`cadmorph model bore 0
b.step`, then `cadmorph info b.step`: the README's first step), and the installed Python
package imports from the prefix's site directory and reads a mesh through the installed
libcadmorph.so; and the README's pip route: a copy of python/ (so that pip's in-place build
does not write into the sources) installed by pip into a fresh venv that sees the system's
cffi, setuptools and NumPy (`--system-site-packages --no-build-isolation`, no network), where
the package opens the prefix's library by its soname (LD_LIBRARY_PATH) or by
CADMORPH_LIBRARY, and reads a mesh.
"""
import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import time

ok = True


def fail(msg):
    global ok
    print("FAIL: " + msg)
    ok = False


def run(cmd, env=None, expect=0):
    t = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    print("$ %s  [%.1f s]" % (" ".join(cmd), time.monotonic() - t), flush=True)
    if r.returncode != expect:
        fail("exit code %d, expected %d\n--- stdout\n%s--- stderr\n%s" %
             (r.returncode, expect, r.stdout, r.stderr))
    return r


def declared_functions(include_dir):
    """cm_ functions declared with CM_API in the installed headers."""
    names = set()
    for h in glob.glob(os.path.join(include_dir, "cadmorph", "*.h")):
        text = open(h).read()
        names |= set(re.findall(r"^CM_API\b[^;{(\n]*?\b(cm_\w+)\s*\(", text, re.MULTILINE))
        # a declaration at file scope without CM_API would be hidden in the shared library
        for m in re.finditer(r"^(?!CM_API|typedef|static|#|\s|/|\*)[^;(\n]*?\b(cm_\w+)\s*\(",
                             text, re.MULTILINE):
            fail("%s: %s is declared without CM_API" % (os.path.basename(h), m.group(1)))
    return names


# prints the library the process mapped (the soname route gives no path), the distribution's
# version, the library's, the mesh's node count and cell count, and whether the package holds
# a compiled module (it must not: ABI mode)
PIP_CHECK = """
import glob, importlib.metadata, os, sys
import cadmorph
lib = [l.split()[-1] for l in open("/proc/self/maps") if "libcadmorph.so" in l][0]
m = cadmorph.read_mesh(sys.argv[1])
so = glob.glob(os.path.join(os.path.dirname(cadmorph.__file__), "*.so"))
print(lib, importlib.metadata.version("cadmorph"), cadmorph.__version__, m.points.shape[0],
      cadmorph.quality(m).cells, len(so))
"""


def pip_route(a, prefix, libdir, version):
    """`pip install --no-build-isolation ./python` into a venv with the system's site packages,
    against the installed libcadmorph (README, section Python; python/README.md)."""
    src = os.path.join(a.work, "python_src")
    shutil.copytree(a.python, src, ignore=shutil.ignore_patterns("build", "*.egg-info",
                                                                  "__pycache__"))
    venv = os.path.join(a.work, "venv")
    run([sys.executable, "-m", "venv", "--system-site-packages", venv])
    py = os.path.join(venv, "bin", "python")
    # --no-index: the machine may have no network; everything comes from the system
    run([os.path.join(venv, "bin", "pip"), "install", "--no-build-isolation", "--no-index",
         "--disable-pip-version-check", src])
    if not ok:
        return
    base = {k: v for k, v in os.environ.items()
            if not k.startswith(("PYTHON", "CADMORPH", "LD_LIBRARY"))}
    base.update(PYTHONDONTWRITEBYTECODE="1")
    soname = os.path.basename(os.path.realpath(os.path.join(libdir, "libcadmorph.so")))
    for how, extra in (("LD_LIBRARY_PATH", {"LD_LIBRARY_PATH": libdir}),
                       ("CADMORPH_LIBRARY",
                        {"CADMORPH_LIBRARY": os.path.join(libdir, "libcadmorph.so")})):
        # from the work directory: the source tree's python/ must not be what is imported
        r = subprocess.run([py, "-c", PIP_CHECK, a.mesh], capture_output=True, text=True,
                           env=dict(base, **extra), cwd=a.work)
        print("$ %s=... %s -c PIP_CHECK" % (how, py), flush=True)
        words = r.stdout.split()
        if r.returncode != 0 or len(words) != 6:
            fail("pip route, %s: %s%s" % (how, r.stdout, r.stderr))
            continue
        lib, dist_version, lib_version, nodes, cells, so = words
        if os.path.realpath(lib) != os.path.join(os.path.realpath(libdir), soname):
            fail("pip route, %s: opened %s, not the prefix's %s" % (how, lib, soname))
        if not dist_version == lib_version == version:
            fail("pip route: the distribution is %s, the library %s, cadmorph.pc %s" %
                 (dist_version, lib_version, version))
        if int(nodes) <= 0 or int(cells) <= 0 or so != "0":
            fail("pip route, %s: %r" % (how, r.stdout))


def main():
    ap = argparse.ArgumentParser()
    for a in ("cmake", "build", "examples", "data", "mesh", "python", "work"):
        ap.add_argument("--" + a, required=True)
    a = ap.parse_args()
    prefix = os.path.join(a.work, "prefix")
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)

    run([a.cmake, "--install", a.build, "--prefix", prefix])
    libdir = os.path.dirname(glob.glob(os.path.join(prefix, "lib*", "**", "libcadmorph.so"),
                                       recursive=True)[0])
    for f in ("libcadmorph.a", "pkgconfig/cadmorph.pc", "cmake/cadmorph/cadmorphConfig.cmake",
              "cmake/cadmorph/cadmorphConfigVersion.cmake"):
        if not os.path.exists(os.path.join(libdir, f)):
            fail("not installed: " + f)
    if not ok:
        return 1

    # the API: exported = declared
    exported = set(run(["nm", "-D", "--defined-only", os.path.join(libdir, "libcadmorph.so")])
                   .stdout.split()[2::3])
    declared = declared_functions(os.path.join(prefix, "include"))
    if declared - exported:
        fail("declared but not exported: " + ", ".join(sorted(declared - exported)))
    if exported - declared:
        fail("exported but not in a header: " + ", ".join(sorted(exported - declared)))
    print("%d functions declared and exported" % len(declared))

    # versions agree
    env = dict(os.environ, PKG_CONFIG_PATH=os.path.join(libdir, "pkgconfig"))
    # the first line; the BLAS and its core follow
    version = run([os.path.join(prefix, "bin", "cadmorph"), "--version"]).stdout.strip().split("\n")[0]
    pc = run(["pkg-config", "--modversion", "cadmorph"], env=env).stdout.strip()
    if version != "cadmorph " + pc or not re.fullmatch(r"\d+\.\d+\.\d+", pc):
        fail("cadmorph --version says %r, cadmorph.pc %r" % (version, pc))

    # the README's first step with the installed program alone
    b_step = os.path.join(a.work, "b.step")
    run([os.path.join(prefix, "bin", "cadmorph"), "model", "bore", "0", b_step])
    info = run([os.path.join(prefix, "bin", "cadmorph"), "info", b_step]).stdout
    if not re.search(r"^solids 1 ", info, re.MULTILINE):
        fail("cadmorph info of the installed model's STEP: %r" % info)

    # the Python package: importable from the prefix's site directory, on the installed library
    pkgs = glob.glob(os.path.join(prefix, "lib*", "python3*", "*-packages", "cadmorph",
                                  "__init__.py"))
    if len(pkgs) != 1:
        fail("the Python package is installed %d times: %s" % (len(pkgs), pkgs))
    else:
        site = os.path.dirname(os.path.dirname(pkgs[0]))
        pyenv = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "CADMORPH"))}
        pyenv.update(PYTHONPATH=site, PYTHONDONTWRITEBYTECODE="1")
        r = run([sys.executable, "-c", "import cadmorph, sys; m = cadmorph.read_mesh(sys.argv[1]); "
                 "print(cadmorph._capi.LIBRARY_PATH, m.points.shape[0], "
                 "cadmorph.quality(m).cells)", a.mesh], env=pyenv)
        words = r.stdout.split()
        if len(words) != 3 or not os.path.realpath(words[0]).startswith(os.path.realpath(prefix)) \
                or int(words[1]) <= 0 or int(words[2]) <= 0:
            fail("the installed Python package: %r" % r.stdout)
    pip_route(a, prefix, libdir, pc)
    if not ok:
        return 1

    # the plate with a hole, its edit, one of another topology, a rigid motion of it
    g0, g1, other, rigid = (os.path.join(a.data, "surface", k + ".step")
                            for k in ("hole_a", "hole_b", "holes2_a", "hole_rigid"))
    m0 = a.mesh

    builds = {
        "config": ["-DCMAKE_PREFIX_PATH=" + prefix],
        "config_static": ["-DCMAKE_PREFIX_PATH=" + prefix, "-DCADMORPH_EXAMPLES_STATIC=ON"],
        "pkgconfig": ["-DCADMORPH_EXAMPLES_PKGCONFIG=ON"],
    }
    bins = {}
    for name, args in builds.items():
        b = os.path.join(a.work, "examples_" + name)
        r = run([a.cmake, "-S", a.examples, "-B", b, "-DCMAKE_BUILD_TYPE=Release"] + args, env=env)
        if r.returncode == 0:
            run([a.cmake, "--build", b], env=env)
        bins[name] = b
    # libcadmorph.a by hand from the .pc's private libraries
    b = os.path.join(a.work, "examples_pkgconfig_static")
    os.makedirs(b)
    cflags = run(["pkg-config", "--cflags", "cadmorph"], env=env).stdout.split()
    libs = run(["pkg-config", "--static", "--libs", "cadmorph"], env=env).stdout.split()
    libs = [os.path.join(libdir, "libcadmorph.a") if x == "-lcadmorph" else x for x in libs]
    for ex in ("morph_mesh", "morph_family"):
        run(["cc", "-std=c11", "-Wall", "-Werror"] + cflags +
            [os.path.join(a.examples, ex + ".c"), "-o", os.path.join(b, ex)] + libs)
    bins["pkgconfig_static"] = b
    if not ok:
        return 1

    for name, b in bins.items():
        linked = run(["ldd", os.path.join(b, "morph_mesh")]).stdout
        shared = "libcadmorph.so" in linked
        if shared != (name in ("config", "pkgconfig")):
            fail("%s: libcadmorph.so %s" % (name, "linked" if shared else "not linked"))
        out = os.path.join(a.work, name + "_m1.vtu")
        r = run([os.path.join(b, "morph_mesh"), g0, g1, m0, out])
        m = re.search(r"(\d+) inverted, boundary (\S+) from G1 \(diagonal (\S+)\)", r.stdout)
        if not m or int(m.group(1)) != 0 or float(m.group(2)) > 1e-9 * float(m.group(3)):
            fail("%s: morph_mesh: %r" % (name, r.stdout))
        if not os.path.exists(out):
            fail("%s: %s not written" % (name, out))
        # the family: G1, a target of another topology (its row says so, exit 2), a rigid motion
        d = os.path.join(a.work, name + "_family")
        os.makedirs(d)
        r = run([os.path.join(b, "morph_family"), g0, m0, d, g1, other, rigid], expect=2)
        rows = r.stdout.splitlines()
        dist = [re.search(r" 0 inverted, boundary (\S+) from it", row) for row in rows]
        if len(rows) != 3 or "does not correspond" not in rows[1] or \
                any(not dist[i] or float(dist[i].group(1)) > 1e-9 for i in (0, 2)):
            fail("%s: morph_family: %r" % (name, r.stdout))
        if sorted(os.listdir(d)) != ["variant_1.vtu", "variant_3.vtu"]:
            fail("%s: morph_family wrote %s" % (name, sorted(os.listdir(d))))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
