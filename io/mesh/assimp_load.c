/* assimp_load.c: mf_assimp_load (mf_assimp_load.h). */
#include "mf_assimp_load.h"

#include <dlfcn.h>
#include <stddef.h>
#include <string.h>

#include "mf_error.h"

#ifndef MF_ASSIMP_SONAME
#error "MF_ASSIMP_SONAME (the soname of the assimp built against) is set by io/meson.build"
#endif

static mf_assimp_api loaded;
static int loaded_ok;

const char *mf_assimp_soname(void)
{
    return MF_ASSIMP_SONAME;
}

/* dlsym's void * into a function pointer: copied as bytes (ISO C has no
 * conversion between the two; POSIX guarantees the representation). */
static int symbol(void *lib, const char *name, void *fn, const char *needed_by)
{
    dlerror();
    void *p = dlsym(lib, name);
    const char *why = dlerror();
    if (why || !p)
        return MF_ERROR(MF_ERR_IO, "%s: reading this polygon file needs %s (assimp), which has no "
                        "%s: %s", needed_by, MF_ASSIMP_SONAME, name, why ? why : "NULL");
    memcpy(fn, &p, sizeof p);
    return 0;
}

int mf_assimp_load(const char *needed_by, const mf_assimp_api **api)
{
    if (loaded_ok) {
        *api = &loaded;
        return 0;
    }
    /* RTLD_LOCAL: nothing else resolves against it; never closed (its
     * C++ statics live to the end of the process, as when it was linked). */
    void *lib = dlopen(MF_ASSIMP_SONAME, RTLD_NOW | RTLD_LOCAL);
    if (!lib)
        return MF_ERROR(MF_ERR_IO, "%s: reading this polygon file needs the library %s (assimp, "
                        "Debian's libassimp5), which could not be loaded: %s",
                        needed_by, MF_ASSIMP_SONAME, dlerror());
    mf_assimp_api a;
    MF_CALL(symbol(lib, "aiImportFile", &a.import_file, needed_by));
    MF_CALL(symbol(lib, "aiReleaseImport", &a.release_import, needed_by));
    MF_CALL(symbol(lib, "aiGetErrorString", &a.get_error_string, needed_by));
    loaded = a;
    loaded_ok = 1;
    *api = &loaded;
    return 0;
}
