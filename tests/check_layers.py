#!/usr/bin/env python3
"""check_layers.py: fail when an #include crosses a layer the wrong way.

The layers, lowest first, and what each may include (its own files and the
layers listed). docs/developer-guide.md draws the same picture; change both
together.

    core/base                       errors, log, utilities
    core/particles, core/output     particle kernel; output data types
    core/parallel                   distributed particle set (MPI, Zoltan)
    core/host                       dictionaries, parameters, registry, sim state
    core/scene                      scene building
    core/run                        time loop, the run's watch
    solvers/                        numerical modules          (core)
    io/                             file formats               (core)
    driver/post                     post-processing            (core, solvers, io)
    driver/app                      the executable             (everything)
    plugins/                        loaded by name             (core only: the installed headers)
    tests/, bench/                  anything

Besides: core includes no hypre, SUNDIALS or HDF5 header; io no hypre or
SUNDIALS; solvers no HDF5. Usage: check_layers.py SOURCE_ROOT
"""
import os
import re
import sys

CORE = ["core/base", "core/particles", "core/parallel", "core/output", "core/host", "core/scene", "core/run"]
ALLOWED = {
    "core/base": ["core/base"],
    "core/particles": ["core/base", "core/particles"],
    "core/output": ["core/base", "core/output"],
    "core/parallel": ["core/base", "core/particles", "core/parallel"],
    "core/host": ["core/base", "core/particles", "core/parallel", "core/output", "core/host"],
    "core/scene": ["core/base", "core/particles", "core/parallel", "core/output", "core/host",
                   "core/scene"],
    "core/run": CORE,
    "solvers": CORE + ["solvers"],
    "io": CORE + ["io"],
    "driver/post": CORE + ["solvers", "io", "driver/post"],
    "driver/app": CORE + ["solvers", "io", "driver/post", "driver/app"],
    "plugins": CORE + ["plugins"],
    "tests": None,  # anything
    "bench": None,
}
# Third-party headers a layer must not see (prefixes of <...> includes).
FORBIDDEN_SYSTEM = {
    "core": ("HYPRE", "_hypre", "hdf5", "H5", "arkode", "sundials", "nvector", "sunlinsol",
             "sunmatrix"),
    "io": ("HYPRE", "_hypre", "arkode", "sundials", "nvector", "sunlinsol", "sunmatrix"),
    "solvers": ("hdf5", "H5"),
}
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def layer_of(rel):
    for name in sorted(ALLOWED, key=len, reverse=True):
        if rel == name or rel.startswith(name + "/"):
            return name
    return None


def main(root):
    files = []
    for top in ("core", "solvers", "io", "driver", "plugins", "tests", "bench"):
        for d, _, names in os.walk(os.path.join(root, top)):
            for n in names:
                if n.endswith((".c", ".h")):
                    files.append(os.path.relpath(os.path.join(d, n), root))
    headers = [f for f in files if f.endswith(".h")]
    by_name = {}
    for h in headers:
        by_name.setdefault(os.path.basename(h), []).append(h)
    errors = []
    for f in sorted(files):
        layer = layer_of(f)
        if layer is None:
            errors.append(f"{f}: in no layer (add its folder to tests/check_layers.py)")
            continue
        allowed = ALLOWED[layer]
        top = f.split("/")[0]
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
            for lineno, line in enumerate(fh, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                kind, name = m.groups()
                if kind == "<":
                    for bad in FORBIDDEN_SYSTEM.get(top, ()):
                        if name.startswith(bad):
                            errors.append(f"{f}:{lineno}: {top}/ must not include <{name}>")
                    continue
                # Resolve as the compiler does: beside the file, then the
                # include folders (a path suffix of a project header).
                here = os.path.normpath(os.path.join(os.path.dirname(f), name))
                if here in files:
                    target = here
                else:
                    cands = [h for h in by_name.get(os.path.basename(name), [])
                             if h.endswith("/" + name) or h == name]
                    if not cands:
                        continue  # generated or system header in quotes
                    if len(cands) > 1:
                        errors.append(f"{f}:{lineno}: \"{name}\" is ambiguous: {cands}")
                        continue
                    target = cands[0]
                tl = layer_of(target)
                if allowed is not None and tl not in allowed:
                    errors.append(f"{f}:{lineno}: includes {target}: layer {layer} may "
                                  f"include only {', '.join(allowed)}")
    for e in errors:
        print(e)
    print(f"check_layers: {len(files)} files, {len(errors)} crossing(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
