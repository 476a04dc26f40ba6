/* mf_assimp_load.h: assimp's C API, loaded with dlopen on first use.
 *
 * Only a case with a polygon file needs assimp; linked in, it and its own
 * libraries (draco, minizip) were mapped, relocated and partly resident in
 * every run (4,228 KiB of the 3-D bench case's peak resident set). The
 * soname is the one the build compiled against (MF_ASSIMP_SONAME,
 * io/meson.build), so the headers' layouts (aiScene, aiMesh) are the
 * loaded library's. */
#ifndef MF_ASSIMP_LOAD_H
#define MF_ASSIMP_LOAD_H

#include <assimp/cimport.h>
#include <assimp/scene.h>

/* The three entry points mesh_import.c calls. */
typedef struct mf_assimp_api {
    const struct aiScene *(*import_file)(const char *path, unsigned int flags);
    void (*release_import)(const struct aiScene *scene);
    const char *(*get_error_string)(void);
} mf_assimp_api;

/* Load assimp once (later calls return the same table) into *api.
 * needed_by names the file that needs it, for the error: MF_ERR_IO naming
 * that file, the library and dlopen's or dlsym's reason. */
int mf_assimp_load(const char *needed_by, const mf_assimp_api **api);

/* The soname loaded (for messages and tests). */
const char *mf_assimp_soname(void);

#endif
