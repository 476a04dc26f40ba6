#!/usr/bin/env python3
"""test_bad_input.py: the bad-input catalogue.

Each entry breaks a copy of a tutorial (or the command line) in one way and
names the exact first line mpsflow must print on stderr; the run must end
with status 1 or 2 (never a signal, never 0) within its time limit. {case}
in an expected line stands for the case folder. Most entries stop at the
dry run (-dryRun); the few that need a run say so.

    test_bad_input.py MPSFLOW TUTORIALS [--record]

--record prints the first lines as they are now instead of checking them
(for writing new entries; every line below was read before it went in).
"""
import concurrent.futures
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import time

FATAL = "--> mpsflow FATAL ERROR: "
EXPECTED = {}  # filled at the end of the file

# (name, tutorial, edits, arguments); the expected first lines are in EXPECTED.
# edits: ("sub", file, regex, replacement) replaces the first match (which
# must exist); ("write", file, text); ("append", file, text); ("fifo", file);
# ("rm", file); ("trunc", file, nbytes).
CTRL, SOLV, FLU, GEO = "system/controlDict", "system/solverDict", "constant/fluids", "constant/geometry"
D = "damBreak2D"
DRY = ["-dryRun"]
CATALOGUE = [
    # ---- the command line --------------------------------------------------
    ("no such case", D, [], ["-case", "{tmp}/nothing", "-dryRun"]),
    ("unknown option", D, [], ["-dryrun"]),
    ("option without value", D, [], ["-dryRun", "-l0"]),
    ("-l0 not a number", D, [], ["-l0", "abc", "-dryRun"]),
    ("-l0 inf", D, [], ["-l0", "inf", "-dryRun"]),
    ("-l0 1e-12", D, [], ["-l0", "1e-12", "-dryRun"]),
    ("-l0 1e-6: billions of particles", D, [], ["-l0", "1e-6", "-dryRun"]),
    ("-endTime inf", D, [], ["-endTime", "inf", "-dryRun"]),
    ("-endTime 1e308", D, [], ["-endTime", "1e308", "-dryRun"]),
    ("-endTime negative", D, [], ["-endTime", "-1", "-dryRun"]),
    ("unknown solver option", D, [], ["-solver", "MSP", "-dryRun"]),
    ("unknown command", D, [], ["modulse"]),
    ("unknown module", D, [], ["modules", "MSP"]),
    # ---- controlDict -------------------------------------------------------
    ("misspelt key", D, [("sub", CTRL, r"^endTime ", "endTme  ")], DRY),
    ("wrong type", D, [("sub", CTRL, r"^endTime .*", "endTime abc;")], DRY),
    ("endTime missing", D, [("sub", CTRL, r"^endTime .*", "")], DRY),
    ("endTime before startTime", D, [("sub", CTRL, r"^startTime .*", "startTime 1;")], DRY),
    ("endTime 1e308", D, [("sub", CTRL, r"^endTime .*", "endTime 1e308;")], DRY),
    ("endTime inf (a word)", D, [("sub", CTRL, r"^endTime .*", "endTime inf;")], DRY),
    ("maxCo 50", D, [("sub", CTRL, r"^maxCo .*", "maxCo 50;")], DRY),
    ("maxCo 0", D, [("sub", CTRL, r"^maxCo .*", "maxCo 0;")], DRY),
    ("maxDi 5", D, [("append", CTRL, "maxDi 5;\n")], DRY),
    ("deltaT 0", D, [("sub", CTRL, r"^deltaT .*", "deltaT 0;")], DRY),
    ("minDeltaT above maxDeltaT", D, [("append", CTRL, "minDeltaT 0.01;\n")], DRY),
    ("writeInterval 0", D, [("sub", CTRL, r"^writeInterval .*", "writeInterval 0;")], DRY),
    ("writeInterval in steps not whole", D,
     [("sub", CTRL, r"^writeControl .*", "writeControl timeStep;"),
      ("sub", CTRL, r"^writeInterval .*", "writeInterval 2.5;")], DRY),
    ("writeControl unknown", D, [("sub", CTRL, r"^writeControl .*", "writeControl runTime;")], DRY),
    ("startFrom unknown", D, [("sub", CTRL, r"^startFrom .*", "startFrom latest;")], DRY),
    ("maxRetries 100", D, [("append", CTRL, "maxRetries 100;\n")], DRY),
    ("maxMemory negative", D, [("append", CTRL, "maxMemory -1;\n")], DRY),
    ("maxMemory too small for the scene", D, [("append", CTRL, "maxMemory 1e-6;\n")], DRY),
    ("adjustTimeStep not a bool", D, [("sub", CTRL, r"^adjustTimeStep .*", "adjustTimeStep maybe;")],
     DRY),
    ("unknown writer", D, [("append", CTRL, "writer vtk;\n")], DRY),
    ("libs not a list", D, [("sub", CTRL, r'^libs .*', 'libs "libkineticEnergy.so";')], DRY),
    ("missing plugin", D, [("sub", CTRL, r'\("libkineticEnergy.so"\)', '("libnoSuchThing.so")')], DRY),
    ("function without type", D, [("sub", CTRL, r"type        kineticEnergy;", "")], DRY),
    ("unknown function type", D, [("sub", CTRL, r"type        kineticEnergy;", "type kinetic;")],
     DRY),
    ("watch: unknown key", D, [("append", CTRL, "watch { energyTol 0.1; }\n")], DRY),
    ("watch: out of range", D, [("append", CTRL, "watch { densityCollapse 2; }\n")], DRY),
    # ---- the dictionary syntax ---------------------------------------------
    ("unbalanced brace", D, [("sub", CTRL, r"^\{$", "{{")], DRY),
    ("key without value", D, [("sub", FLU, r"rho .*", "rho;")], DRY),
    ("missing semicolon", D, [("sub", CTRL, r"^deltaT .*", "deltaT 1e-4")], DRY),
    ("unterminated string", D, [("sub", CTRL, r'\("libkineticEnergy.so"\)', '("libkineticEnergy.so)')],
     DRY),
    ("unterminated comment", D, [("append", GEO, "/* never closed\n")], DRY),
    ("number out of range", D, [("sub", CTRL, r"^deltaT .*", "deltaT 1e999;")], DRY),
    ("unsupported directive", D, [("append", CTRL, "#includeEtc \"caseDicts/setConstraintTypes\"\n")],
     DRY),
    ("missing include", D, [("append", CTRL, "#include \"nothing.inc\"\n")], DRY),
    ("include cycle", D, [("append", CTRL, "#include \"controlDict\"\n")], DRY),
    ("binary file", D, [("write", FLU, "\x00\x01\x02binary")], DRY),
    ("empty file", D, [("write", GEO, "")], DRY),
    ("comments only", D, [("write", GEO, "// nothing here\n/* nor here */\n")], DRY),
    ("a folder as a dictionary", D, [("rm", FLU), ("mkdir", FLU)], DRY),
    ("a FIFO as constant/fluids", D, [("rm", FLU), ("fifo", FLU)], DRY),
    ("a FIFO in an #include", D, [("fifo", "constant/pipe"), ("append", FLU, "#include \"pipe\"\n")],
     DRY),
    ("#include /dev/zero", D, [("append", FLU, "#include \"/dev/zero\"\n")], DRY),
    # ---- solverDict --------------------------------------------------------
    ("no solver named", D, [("sub", SOLV, r"^solver .*", "")], DRY),
    ("unknown solver", D, [("sub", SOLV, r"^solver .*", "solver MSP;")], DRY),
    ("unknown top-level key", D, [("append", SOLV, "MSPCoeffs { beta 0.9; }\n")], DRY),
    ("unknown coefficient", D, [("sub", SOLV, r"    beta .*", "    bta 0.97;")], DRY),
    ("beta out of range", D, [("sub", SOLV, r"    beta .*", "    beta 2;")], DRY),
    ("wallPressureExtrapolated, gradient corrected", D,
     [("sub", SOLV, r"    beta .*", "    beta 0.97; wallPressureExtrapolated yes; gradient corrected;")],
     DRY),
    ("gradientWeight, gradient leastSquares", D,
     [("sub", SOLV, r"    beta .*", "    beta 0.97; gradientWeight wendland; gradient leastSquares;")],
     DRY),
    ("gradientWeight, wall wallWeight", D,
     [("sub", SOLV, r"    beta .*", "    beta 0.97; gradientWeight wendland; wall wallWeight; source mixed;")],
     DRY),
    ("velocityFilter, solver multiFluid", "waterAirDamBreak",
     [("sub", SOLV, r"    outerTolerance .*", "    outerTolerance  1e-3; velocityFilter 0.2;")], DRY),
    ("gradientWeight unknown", D, [("sub", SOLV, r"    beta .*", "    beta 0.97; gradientWeight cubic;")],
     DRY),
    ("reLaplacian out of range", D, [("sub", SOLV, r"    reLaplacian .*", "    reLaplacian 50;")],
     DRY),
    ("unknown pressure solver", D, [("sub", SOLV, r"solver          PCG_BoomerAMG;", "solver PCG_AMG;")],
     DRY),
    ("pressure tolerance 0", D, [("sub", SOLV, r"tolerance       1e-8;", "tolerance 0;")], DRY),
    ("gravity not a vector", D, [("sub", SOLV, r"g           \(0 -9.81 0\);", "g (0 -9.81);")], DRY),
    ("unknown force", D, [("append", SOLV, "forces2 { }\n")], DRY),
    # ---- fluids ------------------------------------------------------------
    ("rho 0", D, [("sub", FLU, r"rho .*", "rho 0;")], DRY),
    ("nu negative", D, [("sub", FLU, r"nu .*", "nu -1e-6;")], DRY),
    ("rho missing", D, [("sub", FLU, r"rho .*", "")], DRY),
    ("no fluid", D, [("write", FLU, "FoamFile { version 2.0; }\n")], DRY),
    ("fluid not a dictionary", D, [("write", FLU, "water 1000;\n")], DRY),
    ("unknown fluid key", D, [("sub", FLU, r"nu .*", "nu 1e-6; mu 1e-3;")], DRY),
    # ---- geometry ----------------------------------------------------------
    ("dimension 4", D, [("sub", GEO, r"^dimension .*", "dimension 4;")], DRY),
    ("particleSpacing 0", D, [("sub", GEO, r"^particleSpacing .*", "particleSpacing 0;")], DRY),
    ("particleSpacing 1e-6", D, [("sub", GEO, r"^particleSpacing .*", "particleSpacing 1e-6;")], DRY),
    ("unknown fluid", D, [("sub", GEO, r"fluid       water;", "fluid       watr;")], DRY),
    ("block max below min", D, [("sub", GEO, r"max         \(0.25 0.5 0\);", "max (-0.25 0.5 0);")],
     DRY),
    ("block type unknown", D, [("sub", GEO, r"type        box;", "type cube;")], DRY),
    ("sphere without radius", D, [("sub", GEO, r"type        box;", "type sphere;")], DRY),
    ("block smaller than l0", D, [("sub", GEO, r"max         \(0.25 0.5 0\);", "max (0.005 0.5 0);")],
     DRY),
    ("block inside a wall", D, [("sub", GEO, r"min         \(0 0 0\);\n        max         \(0.25",
                                 "min (-0.02 0 0);\n        max         (0.25")], DRY),
    ("fluid block outside the tank", D,
     [("sub", GEO, r"min         \(0 0 0\);\n        max         \(0.25 0.5 0\);",
       "min (3 0 0);\n        max (3.25 0.5 0);")], DRY),
    ("fluidBlocks {}", D, [("sub", GEO, r"fluidBlocks\n\{\n(.|\n)*?\n\}\n\nwalls", "fluidBlocks\n{\n}\n\nwalls")],
     DRY),
    ("no fluidBlocks nor walls", D, [("write", GEO, "dimension 2;\nparticleSpacing 0.01;\n")], DRY),
    ("wallLayers 9", D, [("sub", GEO, r"wallLayers  1;", "wallLayers 9;")], DRY),
    ("unknown open face", D, [("sub", GEO, r"open        \(ymax\);", "open (top);")], DRY),
    ("open not a list", D, [("sub", GEO, r"open        \(ymax\);", "open ymax;")], DRY),
    ("mesh file missing", "channelInflow", [("rm", "constant/step.obj")], DRY),
    ("mesh file empty", "channelInflow", [("write", "constant/step.obj", "")], DRY),
    ("mesh file a FIFO", "channelInflow", [("rm", "constant/step.obj"), ("fifo", "constant/step.obj")],
     DRY),
    ("mesh in an unread format", "channelInflow",
     [("write", "constant/step.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
      ("sub", GEO, r'file        "step.obj";', 'file "step.off";')], DRY),
    ("OBJ cut mid-face", "boxFilling", [("trunc", "constant/triSurface/box.obj", -4)], DRY),
    ("mesh in millimetres", "boxFilling", [("sub", GEO, r'file        "box.obj";', 'file "box.obj"; scale 1000;')],
     DRY),
    ("obstacle overlapping fluid", "boxFilling",
     [("append", GEO, "fluidBlocks { pool { type box; min (0.12 0.4 0.12); max (0.48 0.68 0.68); fluid water; } }\n")],
     DRY),
    ("inlet 4 m outside the domain", "channelInflow",
     [("sub", GEO, r"min         \(-0.08 0.1 0\);\n        max         \(0 0.2 0\);",
       "min (-4.08 0.1 0);\n        max (-4 0.2 0);")], DRY),
    ("nozzle outside the domain", "boxFilling",
     [("sub", GEO, r"centre \(0.3 0.76 0.25\)", "centre (5 0.76 0.25)")], DRY),
    ("inlet velocity off axis", "channelInflow",
     [("sub", GEO, r"velocity    \(1 0 0\);        // the mean", "velocity (1 1 0); // the mean")],
     DRY),
    # ---- commands ----------------------------------------------------------
    ("validate without output", D, [], ["validate"]),
    ("validate without metric", D, [("rm", "validation/metric")], ["validate"]),
    ("unknown metric", D, [("sub", "validation/metric", r"^metric .*", "metric surge;")], ["validate"]),
    ("restart without snapshots", D, [], ["-latestTime"]),
    ("compareDict unknown key", "hydrostatic2D", [("append", "system/compareDict", "variant { }\n")],
     ["compare", "-solvers", "(MPS_plain)", "-resolutions", "(0.05)"]),
    ("stabilityDict unknown key", D, [("append", "system/stabilityDict", "sweep { }\n")],
     ["stability", "-solvers", "(MPS)"]),
    # ---- runs that fail --------------------------------------------------------
    ("solve not converging", D,
     [("sub", SOLV, r"    tolerance       1e-8;", "    tolerance 1e-8; maxIter 2;")],
     ["-endTime", "0.05", "-l0", "0.02"]),
]

# Entries whose first line depends on the machine (its memory) or on the
# last digits of a solver's arithmetic: a pattern.
PATTERNS = {
    "missing plugin":
        r"^--> mpsflow FATAL ERROR: cannot load plugin 'libnoSuchThing\.so' \(tried "
        r"libnoSuchThing\.so, \{bin\}/\.\./plugins/libnoSuchThing\.so, .*\): .*cannot open shared "
        r"object file: No such file or directory\. Set MPSFLOW_PLUGIN_PATH to the folder that "
        r"holds it$",
    "solve not converging":
        r"^--> mpsflow FATAL ERROR: unstable \(pressureSolve\) at time 7\.5e-06, step 1: "
        r"PCG_BoomerAMG not converged after 2 iterations \(relative residual [0-9.e+-]+, from "
        r"1\); largest residual at .* particle id \d+ at \(.*\)$",
    "-l0 1e-6: billions of particles":
        r"^--> mpsflow FATAL ERROR: \{case\}/constant/geometry:1:1: the scene would make about "
        r"1\.25e\+11 particles at l0 = 1e-06 m, .* GB at \d+ bytes a particle .*more than "
        r"maxMemory = .* GB \(80% of this .*\): use a larger particleSpacing \(or -l0\), or raise "
        r"maxMemory in system/controlDict$",
    "particleSpacing 1e-6":
        r"^--> mpsflow FATAL ERROR: \{case\}/constant/geometry:1:1: the scene would make about "
        r"1\.25e\+11 particles at l0 = 1e-06 m, .*raise maxMemory in system/controlDict$",
}


def edit(case, op):
    kind, rel = op[0], op[1]
    path = os.path.join(case, rel)
    if kind == "sub":
        text = open(path).read()
        new, n = re.subn(op[2], op[3], text, count=1, flags=re.M)
        if n != 1:
            raise SystemExit(f"catalogue error: /{op[2]}/ not found in {rel}")
        open(path, "w").write(new)
    elif kind == "write":
        open(path, "wb").write(op[2].encode("latin-1"))
    elif kind == "append":
        open(path, "a").write(op[2])
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "mkdir":
        os.mkdir(path)
    elif kind == "rm":
        os.remove(path)
    elif kind == "trunc":
        size = os.path.getsize(path)
        os.truncate(path, size + op[2] if op[2] < 0 else op[2])


def run(command, env, cwd):
    try:
        r = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                           timeout=120, cwd=cwd)
        return r.returncode, r.stderr.decode("utf-8", "replace"), r.stdout.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        return "timeout", "", ""


def after_failed_run(case, out):
    """A run that stops keeps what it had: retries said, every snapshot
    readable, no temporary file left, the ending (unstable) in output/runSummary."""
    problems = []
    if not re.search(r"retrying with deltaT.*retry 4 of 4", out):
        problems.append("no 'retry 4 of 4' in the log")
    snaps = sorted(f for f in os.listdir(os.path.join(case, "output")) if f.endswith(".h5"))
    if not snaps:
        problems.append("no snapshot left")
    for f in snaps:
        r = subprocess.run(["h5dump", "-H", os.path.join(case, "output", f)],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if r.returncode != 0:
            problems.append(f"{f} is not readable")
    if any(f.endswith(".tmp") for f in os.listdir(os.path.join(case, "output"))):
        problems.append("a .tmp file was left")
    summary = os.path.join(case, "output", "runSummary")
    if not os.path.exists(summary) or not re.search(r"^status +unstable;", open(summary).read(), re.M):
        problems.append("no runSummary saying unstable")
    return problems


AFTER = {"solve not converging": after_failed_run}


def first_line(text):
    for line in text.splitlines():
        if line.strip():
            return line.rstrip()
    return ""


def main():
    mpsflow, tutorials = sys.argv[1], sys.argv[2]
    record = "--record" in sys.argv
    tmp = tempfile.mkdtemp(prefix="mpsflow-bad-")
    env = dict(os.environ, OMP_NUM_THREADS="1")
    passed = failed = 0
    t0 = time.time()
    jobs = []
    # The runs wait on MPI's start-up far more than they compute: four at a time.
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=4)
    try:
        for k, (name, tutorial, edits, args) in enumerate(CATALOGUE):
            case = os.path.join(tmp, f"c{k:03d}")
            shutil.copytree(os.path.join(tutorials, tutorial), case,
                            ignore=shutil.ignore_patterns("output", "postProcessing", "log.*",
                                                          "compare", "stability"))
            for op in edits:
                edit(case, op)
            argv = [a.replace("{tmp}", tmp) for a in args]
            command = [mpsflow] + argv + ([] if "-case" in argv else ["-case", case])
            jobs.append((name, case, pool.submit(run, command, env, tmp)))
        for name, case, job in jobs:
            status, err, out = job.result()
            line = first_line(err).replace(case, "{case}").replace(tmp, "{tmp}")
            line = line.replace(os.path.dirname(mpsflow), "{bin}")
            expected = EXPECTED.get(name)
            if record:
                print(f"    {name!r}:\n        {line!r},")
                continue
            problems = []
            if status not in (1, 2):
                problems.append(f"exit status {status} (a crash, a hang or a success)")
            if name in PATTERNS:
                if not re.match(PATTERNS[name], line):
                    problems.append(f"first line does not match /{PATTERNS[name]}/")
            elif expected is not None and line != expected:
                problems.append(f"first line differs; expected\n         {expected}")
            elif expected is None:
                problems.append("no expected line in the catalogue")
            if name in AFTER:
                problems += AFTER[name](case, out)
            if problems:
                failed += 1
                print(f"FAIL {name}: " + "; ".join(problems) + f"\n     got {line}")
            else:
                passed += 1
                print(f"ok   {name}: {line[len(FATAL):] if line.startswith(FATAL) else line}"[:200])
    finally:
        pool.shutdown()
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{len(CATALOGUE)} broken cases in the catalogue; {passed} passed, {failed} failed "
          f"({time.time() - t0:.1f} s)")
    return 1 if failed else 0


# The exact first line of stderr of each entry, as read and checked when it
# went in ({case}: the case folder, {tmp}: the test's folder, {bin}: mpsflow's).
EXPECTED.update({
    'no such case':
        "--> mpsflow FATAL ERROR: {tmp}/nothing/system/controlDict: cannot open (No such file or directory); is '{tmp}/nothing' a case directory?",
    'unknown option':
        "--> mpsflow FATAL ERROR: unknown option '-dryrun'; did you mean '-dryRun'? (see mpsflow -help)",
    'option without value':
        "--> mpsflow FATAL ERROR: -l0 takes a positive finite number, not '-case'",
    '-l0 not a number':
        "--> mpsflow FATAL ERROR: -l0 takes a positive finite number, not 'abc'",
    '-l0 inf':
        "--> mpsflow FATAL ERROR: -l0 takes a positive finite number, not 'inf'",
    '-l0 1e-12':
        '--> mpsflow FATAL ERROR: -l0 1e-12 is out of range [1e-09, 1e+06] (l0, the initial particle spacing, m (-l0 overrides it, in the same range). The numerics are scale-free; what bounds l0 is the count it makes, checked against maxMemory before any particle is made)',
    '-endTime inf':
        "--> mpsflow FATAL ERROR: -endTime takes a positive finite number, not 'inf'",
    '-endTime 1e308':
        '--> mpsflow FATAL ERROR: -endTime: endTime 1e+308 is out of range [0, 1e+09] (time to stop, s; a double time holds 16 digits, so at 1e9 s it still resolves steps of 1e-6 s: beyond that, steps would be lost in rounding)',
    '-endTime negative':
        "--> mpsflow FATAL ERROR: -endTime takes a positive finite number, not '-1'",
    'unknown solver option':
        "--> mpsflow FATAL ERROR: unknown solver module 'MSP' (did you mean 'MPS'?); valid solver modules: MPS, multiFluid, MAFL",
    'unknown command':
        "mpsflow: unknown command 'modulse' (did you mean 'modules'?)",
    'unknown module':
        "--> mpsflow FATAL ERROR: no module or case dictionary named 'MSP' (did you mean 'MPS'?); known: MPS, multiFluid, MAFL, PCG_BoomerAMG, PCG_diagonal, upwind, QUICK, gravity, surfaceTension, drag, attraction, velocityRegion, pathFollow, surface, levelSet, blobby, hdf5, surgeFront, hydrostaticPressure, scalarAdvection, volumeFlux, laplacePressure, oscillationPeriod, layering, rayleighTaylor, fluidSurgeFront, poiseuille, couette, sloshingPeriod, containment, restingTank, targetFraction, floatingDraft, waterEntryDepth, controlDict, watch, geometry, fluids, validation, compareDict, stabilityDict, decomposeParDict",
    'misspelt key':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:15:1: unknown key 'endTme' in '(top level)' (did you mean 'endTime'?); valid keys: application, startTime, endTime, deltaT, adjustTimeStep, maxCo, maxDi, maxDeltaT, minDeltaT, writeControl, writeInterval, writer, startFrom, maxRetries, maxMemory, stopAt, runTimeModifiable, purgeWrite, FoamFile, libs, functions, watch, writerCoeffs",
    'wrong type':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:15:9: key 'endTime': expected a number, found word 'abc'",
    'endTime missing':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:1:1: missing required key 'endTime' in '(top level)' (scalar: time to stop, s; a double time holds 16 digits, so at 1e9 s it still resolves steps of 1e-6 s: beyond that, steps would be lost in rounding)",
    'endTime before startTime':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:15:1: endTime (0.6) must be after startTime (1)',
    'endTime 1e308':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:15:1: key 'endTime': 1e+308 is out of range [0, 1e+09] (time to stop, s; a double time holds 16 digits, so at 1e9 s it still resolves steps of 1e-6 s: beyond that, steps would be lost in rounding)",
    'endTime inf (a word)':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:15:9: key 'endTime': expected a number, found word 'inf'",
    'maxCo 50':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:19:1: key 'maxCo': 50 is out of range [1e-06, 2] (largest Courant number |u| dt / l0. The explicit half of the semi-implicit MPS step moves a particle Co l0 before the pressure equation sees it: at Co = 1 it reaches its neighbour's place and the pressure can no longer keep them apart (damBreak2D is unstable from 1); up to 2 is allowed so that a stability map can show that)",
    'maxCo 0':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:19:1: key 'maxCo': 0 is out of range [1e-06, 2] (largest Courant number |u| dt / l0. The explicit half of the semi-implicit MPS step moves a particle Co l0 before the pressure equation sees it: at Co = 1 it reaches its neighbour's place and the pressure can no longer keep them apart (damBreak2D is unstable from 1); up to 2 is allowed so that a stability map can show that)",
    'maxDi 5':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:35:1: key 'maxDi': 5 is out of range [0, 2] (largest viscous number nu dt / l0^2 of the explicit viscous term (0: no viscous limit). Forward Euler on the Laplacian of eq. 7 is stable to about 1 on a lattice (measured on poiseuille2D: stable at 1, unstable from 1.25): beyond 2 it never is)",
    'deltaT 0':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:17:1: key 'deltaT': 0 is out of range [1e-12, 1e+06] (first time step (every step when adjustTimeStep is off; the last one is shortened to land on endTime and on write times), s)",
    'minDeltaT above maxDeltaT':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:35:1: minDeltaT (0.01 s) must be below maxDeltaT (0.001 s): every adjustable step would stop the run as unstable',
    'writeInterval 0':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:23:1: key 'writeInterval': 0 is out of range [1e-12, 1e+09] (time (s, adjustableRunTime: steps land on each write time) or steps (timeStep: a whole number >= 1) between snapshots)",
    'writeInterval in steps not whole':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:23:1: writeInterval 2.5: with writeControl timeStep it counts steps, a whole number >= 1',
    'writeControl unknown':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:22:1: key 'writeControl': unknown choice 'runTime'; valid: adjustableRunTime, timeStep",
    'startFrom unknown':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:13:1: key 'startFrom': unknown choice 'latest'; valid: startTime, latestTime",
    'maxRetries 100':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:35:1: key 'maxRetries': 100 is out of range [0, 20] (retries of a failed step, each with half the time step (20 halvings: a millionth))",
    'maxMemory negative':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:35:1: key 'maxMemory': -1 is out of range [0, 1e+06] (GB the scene may need by the memory estimate (particles times bytes a particle), checked before any particle is made; 0: 80% of this machine's memory (or of the cgroup's limit))",
    'maxMemory too small for the scene':
        '--> mpsflow FATAL ERROR: {case}/constant/geometry:1:1: the scene would make about 2.85e+03 particles at l0 = 0.01 m, 0.00456 GB at 1604 bytes a particle (particle arrays, neighbour lists within 3.1 l0, the pressure matrix), more than maxMemory = 1e-06 GB (set in system/controlDict): use a larger particleSpacing (or -l0), or raise maxMemory in system/controlDict',
    'adjustTimeStep not a bool':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:18:16: key 'adjustTimeStep': expected a boolean (true/false, yes/no, on/off), found word 'maybe'",
    'unknown writer':
        "--> mpsflow FATAL ERROR: unknown writer module 'vtk'; valid writer modules: hdf5",
    'libs not a list':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:25:1: \'libs\' takes a list, e.g. libs ("libprobes.so");',
    'function without type':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:29:5: missing key 'type' in dictionary 'functions/energy'",
    'unknown function type':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:29:5: function 'energy': unknown functionObject module 'kinetic'; valid functionObject modules: surface, kineticEnergy",
    'watch: unknown key':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:35:9: unknown key 'energyTol' in 'watch'; valid keys: enabled, energyTolerance, densityCollapse, availableEnergy, availableEnergyTolerance",
    'watch: out of range':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:35:9: key 'densityCollapse': 2 is out of range [0, 1] (mean fluid number density below this fraction of n0 means the fluid blew apart)",
    'unbalanced brace':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:5:2: expected a key (a word), found '{'",
    'key without value':
        "--> mpsflow FATAL ERROR: {case}/constant/fluids:11:5: key 'rho' has no value: expected a value before ';'",
    'missing semicolon':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:17:1: key 'deltaT': expected a number, found 3 items (is a ';' missing at the end of line 17?)",
    'unterminated string':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:25:18: unterminated string: this \'"\' is never closed',
    'unterminated comment':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:37:1: unterminated comment: this '/*' is never closed by '*/'",
    'number out of range':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:17:8: number 1e999 is out of range (beyond +-1.8e308)',
    'unsupported directive':
        "--> mpsflow FATAL ERROR: {case}/system/controlDict:35:1: unsupported directive '#includeEtc' (only #include is supported)",
    'missing include':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:35:1: cannot open #include file "nothing.inc" (No such file or directory)',
    'include cycle':
        '--> mpsflow FATAL ERROR: {case}/system/controlDict:35:1: #include cycle: "controlDict" ({case}/system/controlDict) is already being read',
    'binary file':
        '--> mpsflow FATAL ERROR: {case}/constant/fluids:1:1: binary data (byte 0x00): this is not a text dictionary',
    'empty file':
        '--> mpsflow FATAL ERROR: {case}/constant/geometry:1:1: empty dictionary file: expected at least one entry',
    'comments only':
        '--> mpsflow FATAL ERROR: {case}/constant/geometry:1:1: empty dictionary file: expected at least one entry',
    'a folder as a dictionary':
        '--> mpsflow FATAL ERROR: {case}/constant/fluids: is a folder, not a regular file: not a dictionary',
    'a FIFO as constant/fluids':
        '--> mpsflow FATAL ERROR: {case}/constant/fluids: is a FIFO (named pipe), not a regular file: not a dictionary',
    'a FIFO in an #include':
        '--> mpsflow FATAL ERROR: {case}/constant/fluids:14:1: #include file "pipe" is a FIFO (named pipe), not a regular file: not a dictionary',
    '#include /dev/zero':
        '--> mpsflow FATAL ERROR: {case}/constant/fluids:14:1: #include file "/dev/zero" is a character device, not a regular file: not a dictionary',
    'no solver named':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:1:1: missing key 'solver' in dictionary '(top level)'",
    'unknown solver':
        "--> mpsflow FATAL ERROR: unknown solver module 'MSP' (did you mean 'MPS'?); valid solver modules: MPS, multiFluid, MAFL",
    'unknown top-level key':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:36:1: unknown key 'MSPCoeffs' in '(top level)' (did you mean 'MPSCoeffs'?); valid keys: solver, pressure, viscosity, forces, FoamFile, MPSCoeffs, multiFluidCoeffs, MAFLCoeffs",
    'unknown coefficient':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:20:5: unknown key 'bta' in 'MPSCoeffs' (did you mean 'beta'?); valid keys: reNumberDensity, reGradient, reLaplacian, beta, relaxation, compressibility, clipNegativePressure, gradientPmin, gradientWeight, wallPressureExtrapolated, velocityFilter, scheme, source, densityFactor, gradient, laplacian, shifting, shiftCoefficient, shiftMax, surfaceDetection, asymmetry, retrySource, collision, collisionAfterCorrection, collisionDistance, restitution, reorderInterval, viscosity, periodicLength, periodicOrigin, wall",
    'velocityFilter, solver multiFluid':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:34:27: key 'velocityFilter': only solver MPS has it (a composing solver's phases do not take it); set it to 0 there",
    'wallPressureExtrapolated, gradient corrected':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:20:16: key 'wallPressureExtrapolated': it continues the walls' pressure for gradient paper (eq. 5) only; set it to no there",
    'gradientWeight, gradient leastSquares':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:20:16: key 'gradientWeight': it weights eq. 5's sum (gradient paper or corrected), not the least-squares gradient; set it to paper there",
    'gradientWeight, wall wallWeight':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:20:41: wall wallWeight: the wall tables integrate the paper's weight (set gradientWeight paper;); use wall particles; (the default) there",
    'gradientWeight unknown':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:20:16: key 'gradientWeight': unknown choice 'cubic'; valid: paper, wendland, wendlandW",
    'beta out of range':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:20:5: key 'beta': 2 is out of range [0.5, 1] (free surface where n* < beta n0 (eq. 18))",
    'reLaplacian out of range':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:19:5: key 'reLaplacian': 50 is out of range [1.01, 10] (radius of the Laplacian (viscosity, pressure equation), in l0)",
    'unknown pressure solver':
        "--> mpsflow FATAL ERROR: unknown pressure module 'PCG_AMG'; valid pressure modules: PCG_BoomerAMG, PCG_diagonal",
    'pressure tolerance 0':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:26:5: key 'tolerance': 0 is out of range [1e-16, 1] (relative residual ||b - A x|| / ||b|| to reach)",
    'gravity not a vector':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:31:5: force 'gravity': {case}/system/solverDict:33:11: key 'g': expected a vector (a list of 3 numbers, like (0 -9.81 0)), found a list of 2 items",
    'unknown force':
        "--> mpsflow FATAL ERROR: {case}/system/solverDict:36:1: unknown key 'forces2' in '(top level)' (did you mean 'forces'?); valid keys: solver, pressure, viscosity, forces, FoamFile, MPSCoeffs, multiFluidCoeffs, MAFLCoeffs",
    'rho 0':
        "--> mpsflow FATAL ERROR: {case}/constant/fluids:11:5: key 'rho': 0 is out of range [0.001, 1e+06] (density, kg/m^3. One fluid's density only scales the pressure; between fluids the ratio conditions the pressure equation: from hydrogen (0.09) past mercury (13,600), with a margin)",
    'nu negative':
        "--> mpsflow FATAL ERROR: {case}/constant/fluids:12:5: key 'nu': -1e-06 is out of range [0, 10000] (kinematic viscosity, m^2/s (water 1e-6, honey 1e-2); the explicit term limits dt to maxDi l0^2 / nu, the implicit one (viscosity implicit) does not)",
    'rho missing':
        "--> mpsflow FATAL ERROR: {case}/constant/fluids:9:1: missing required key 'rho' in 'water' (scalar: density, kg/m^3. One fluid's density only scales the pressure; between fluids the ratio conditions the pressure equation: from hydrogen (0.09) past mercury (13,600), with a margin)",
    'no fluid':
        '--> mpsflow FATAL ERROR: {case}/constant/fluids:1:1: no fluid defined (add e.g. water { rho 1000; nu 1e-6; })',
    'fluid not a dictionary':
        "--> mpsflow FATAL ERROR: {case}/constant/fluids:1:1: 'water' must be a fluid sub-dictionary { rho ...; nu ...; }",
    'unknown fluid key':
        "--> mpsflow FATAL ERROR: {case}/constant/fluids:12:14: unknown key 'mu' in 'water' (did you mean 'nu'?); valid keys: rho, nu, sigma",
    'dimension 4':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:11:1: key 'dimension': 4 is out of range [2, 3] (2 or 3)",
    'particleSpacing 0':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:12:1: key 'particleSpacing': 0 is out of range [1e-09, 1e+06] (l0, the initial particle spacing, m (-l0 overrides it, in the same range). The numerics are scale-free; what bounds l0 is the count it makes, checked against maxMemory before any particle is made)",
    'unknown fluid':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:21:9: fluid block 'column': unknown fluid 'watr' (did you mean 'water'?); constant/fluids defines: water",
    'block max below min':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:16:5: fluid block 'column': max must exceed min on every axis",
    'block type unknown':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:18:9: key 'type': unknown choice 'cube'; valid: box, sphere, mesh",
    'sphere without radius':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:16:5: fluid block 'column': type sphere needs a radius > 0 (and a centre)",
    'block smaller than l0':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:16:5: fluid block 'column' is smaller than one particle spacing (0.01): no particle placed",
    'block inside a wall':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:16:5: fluid block 'column': 100 pairs of particles start closer than l0/2 = 0.005 m, e.g. a fluid particle at (-0.015 0.005 0) and a dummy particle at (-0.015 0.005 0) of {case}/constant/geometry:27:5: wall 'tank': do two fluid blocks overlap, or does a block reach into a wall or an obstacle?",
    'fluid block outside the tank':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:16:5: fluid block 'column': fluid at (3.005 0.005 0) is outside wall box 1 (0 0 0) to (2 0.6 0), past its xmax face: the run would stop at step 0 (throughWall). Move the block inside the walls, or open that face",
    'fluidBlocks {}':
        '--> mpsflow FATAL ERROR: {case}/constant/geometry:14:1: the scene has no fluid: fluidBlocks holds no block, and no inlet or emitter adds any. Add a block, e.g. fluidBlocks { column { type box; min (0 0 0); max (0.1 0.2 0); fluid water; } }',
    'no fluidBlocks nor walls':
        '--> mpsflow FATAL ERROR: {case}/constant/geometry:1:1: the geometry has neither fluidBlocks nor walls',
    'wallLayers 9':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:33:9: key 'wallLayers': 9 is out of range [1, 3] (layers of wall particles (in the pressure equation))",
    'unknown open face':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:32:15: wall 'tank': unknown face in 'open'; faces are xmin, xmax, ymin, ymax, zmin, zmax",
    'open not a list':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:32:9: wall 'tank': 'open' takes a list of faces, e.g. (ymax)",
    'mesh file missing':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:38:9: wall 'channel': polygon file 'step.obj' not found (looked for {case}/constant/step.obj and {case}/constant/triSurface/step.obj)",
    'mesh file empty':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:38:9: wall 'channel': {case}/constant/step.obj: the file is empty (0 bytes)",
    'mesh file a FIFO':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:38:9: wall 'channel': {case}/constant/step.obj: is a FIFO (named pipe), not a regular file: not a polygon file",
    'mesh in an unread format':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:38:9: wall 'channel': {case}/constant/step.off: not a polygon format read here (the name must end in .obj, .stl or .ply; convert the file, e.g. with meshlab or Blender)",
    'OBJ cut mid-face':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:26:9: wall 'box': {case}/constant/triSurface/box.obj holds 1 points or lines beside its triangles (a file cut short in the middle of a face, or edges drawn in it); only triangles and polygons make surfaces: repair or re-export the file",
    'mesh in millimetres':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:23:5: wall 'box': {case}/constant/triSurface/box.obj (800 m across, 3.2e+06 m^2) would need about 1.6e+10 particles at l0 = 0.04 m: is the file in millimetres (`scale 0.001;`), or l0 too small?",
    'obstacle overlapping fluid':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:59:15: fluid block 'pool': 430 pairs of particles start closer than l0/2 = 0.02 m, e.g. a fluid particle at (0.14 0.42 0.14) and a wall particle at (0.14 0.42 0.14) of {case}/constant/geometry:31:1: obstacles: do two fluid blocks overlap, or does a block reach into a wall or an obstacle?",
    'inlet 4 m outside the domain':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:44:5: inlet 'left' at (-4.08 0.1 0) to (-4 0.2 0) does not reach the domain the walls span, (-0.115 -0.035 0) to (2.115 0.235 0): its fluid would never enter",
    'nozzle outside the domain':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:52:5: nozzle 'nozzle1' at (5 0.76 0.25) does not reach the domain the walls span, (-0.14 -0.14 -0.14) to (0.94 0.94 0.94): its fluid would never enter",
    'inlet velocity off axis':
        "--> mpsflow FATAL ERROR: {case}/constant/geometry:48:9: inlet 'left': velocity (1 1 0) must be non-zero and along a coordinate axis (the inflow direction)",
    'validate without output':
        '--> mpsflow FATAL ERROR: {case}/output: no output folder: run the case first (mpsflow -case {case})',
    'validate without metric':
        "--> mpsflow FATAL ERROR: cannot open dictionary file '{case}/validation/metric' (No such file or directory)",
    'unknown metric':
        "--> mpsflow FATAL ERROR: {case}/validation/metric:14:1: unknown metric module 'surge'; valid metric modules: surgeFront, hydrostaticPressure, scalarAdvection, volumeFlux, laplacePressure, oscillationPeriod, layering, rayleighTaylor, fluidSurgeFront, poiseuille, couette, sloshingPeriod, containment, restingTank, targetFraction, floatingDraft, waterEntryDepth",
    'restart without snapshots':
        '--> mpsflow FATAL ERROR: no snapshot to restart from in {case}/output (run without -latestTime first)',
    'compareDict unknown key':
        "--> mpsflow FATAL ERROR: {case}/system/compareDict:26:1: unknown key 'variant' in '(top level)' (did you mean 'variants'?); valid keys: variants, FoamFile",
    'stabilityDict unknown key':
        "--> mpsflow FATAL ERROR: {case}/system/stabilityDict:39:1: unknown key 'sweep' in '(top level)' (did you mean 'sweeps'?); valid keys: endTime, overrides, sweeps, FoamFile",
})

if __name__ == "__main__":
    sys.exit(main())
