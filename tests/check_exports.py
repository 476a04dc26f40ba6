#!/usr/bin/env python3
"""check_exports.py: fail when the executable exports a symbol that is not
part of the plugin API.

Our code is compiled with -fvisibility=hidden; the installed headers (the
plugin API, listed in core/meson.build's install_headers) push visibility
default, so the executable's dynamic symbol table holds what they declare
and nothing else of ours. Besides those, it holds what the C runtime and
the linker put there (_start, _edata, ...) and data of shared libraries
copied into the executable (stdout, ompi_mpi_comm_world: R_*_COPY
relocations), AddressSanitizer's __odr_asan.<name> beside an exported
global, and the locks of OpenMP critical sections (.gomp_critical_user_*). Every other exported symbol must start with mf_ (or MF_).

Usage: check_exports.py EXECUTABLE [PLUGIN.so ...]
Each plugin's undefined mf_ symbols must be exported by the executable.
"""
import re
import subprocess
import sys

RUNTIME = {"_start", "_init", "_fini", "_edata", "_end", "__bss_start", "__data_start",
           "data_start", "_IO_stdin_used", "__dso_handle", "__libc_csu_init",
           "__libc_csu_fini"}

# The lock of an OpenMP named critical section (clang names the one of its
# reductions so): the compiler makes it a common symbol, shared by design.
GOMP_LOCK = ".gomp_critical_user_"


def dynamic_symbols(path, flag):
    out = subprocess.run(["nm", "-D", flag, path], check=True, capture_output=True,
                         text=True).stdout
    names = set()
    for line in out.splitlines():
        parts = line.split()
        if parts:
            names.add(parts[-1].split("@")[0])
    return names


def copied(path):
    out = subprocess.run(["readelf", "-rW", path], check=True, capture_output=True,
                         text=True).stdout
    names = set()
    for line in out.splitlines():
        m = re.search(r"R_\w+_COPY\s+\S+\s+(\S+)", line)
        if m:
            names.add(m.group(1).split("@")[0])
    return names


def main(argv):
    exe = argv[1]
    exported = dynamic_symbols(exe, "--defined-only")
    # AddressSanitizer adds an __odr_asan.<name> indicator beside each exported
    # global: it stands for <name>.
    bad = sorted(s for s in exported - RUNTIME - copied(exe)
                 if not re.match(r"(__odr_asan\.)?(mf|MF)_", s) and not s.startswith(GOMP_LOCK))
    api = sorted(s for s in exported if re.match(r"(mf|MF)_", s))
    status = 0
    if bad:
        print(f"check_exports: {exe} exports {len(bad)} symbol(s) outside the plugin API "
              "(give them the mf_ prefix and declare them in an installed header, or keep "
              "them out of the installed headers):")
        for s in bad:
            print("   ", s)
        status = 1
    for plugin in argv[2:]:
        missing = sorted(s for s in dynamic_symbols(plugin, "--undefined-only")
                         if re.match(r"(mf|MF)_", s) and s not in exported)
        if missing:
            print(f"check_exports: {plugin} needs {', '.join(missing)}, which {exe} "
                  "does not export")
            status = 1
    print(f"check_exports: {len(api)} API symbol(s) exported, {len(bad)} outside the API")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv))
