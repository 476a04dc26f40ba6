/* fuzz_mesh.c: polygon files into the scene (io/mesh/mesh_import.c through
 * assimp, then core/scene: mf_trimesh_check, the winding number, and a scene
 * with the mesh as a wall and as a fluid block on a coarse lattice).
 *
 * The first byte picks the format (OBJ, STL, PLY: what mf_mesh_import
 * reads; assimp's OFF reader, tried at first, crashed), the rest is the file. Any input must end in particles or a clean error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_mesh_import.h"
#include "mf_particles.h"
#include "mf_scene.h"
#include "mf_walls.h"
#include "mf_trimesh.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0;
}

/* A scene of the mesh as `role` (walls or fluidBlocks) at spacing l0. */
static void build_scene(const char *path, const char *role, double l0)
{
    char text[2048];
    snprintf(text, sizeof text,
             "dimension 3;\nparticleSpacing %.17g;\n%s { m { type mesh; file \"%s\"; %s } }\n",
             l0, role, path, strcmp(role, "fluidBlocks") == 0 ? "fluid water;" : "");
    mf_dict *geometry = NULL, *fluids = NULL;
    static const char fluid_text[] = "water { rho 1000; nu 1e-6; }";
    if (mf_dict_parse_string(text, strlen(text), "geometry", &geometry) != 0 ||
        mf_dict_parse_string(fluid_text, sizeof fluid_text - 1, "fluids", &fluids) != 0) {
        fprintf(stderr, "harness dictionaries do not parse: %s\n", mf_error_message());
        abort();
    }
    mf_sim sim;
    memset(&sim, 0, sizeof sim);
    mf_log log;
    FILE *null = fopen("/dev/null", "w");
    mf_log_init(&log, null, MF_LOG_QUIET);
    sim.log = &log;
    const mf_trimesh_reader reader = mf_mesh_import_reader();
    if (mf_scene_read_fluids(fluids, &sim) == 0 &&
        mf_scene_build_with_reader(geometry, 0, &sim, NULL, &reader) == 0)
        mf_scene_check_overlap(&sim);
    mf_error_clear();
    mf_walls_destroy(sim.walls);
    mf_particles_destroy(sim.p);
    fclose(null);
    mf_dict_free(geometry);
    mf_dict_free(fluids);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const ext[] = {"obj", "stl", "ply"}; /* what mf_mesh_import reads */
    if (size < 1)
        return 0;
    char path[700];
    snprintf(path, sizeof path, "%s/mesh.%s", fuzz_tmp_dir(), ext[data[0] % 3]);
    if (!fuzz_write_file(fuzz_tmp_dir(), strrchr(path, '/') + 1, data + 1, size - 1))
        abort();
    mf_trimesh m;
    mf_trimesh_init(&m);
    int rc = mf_mesh_import(path, &m);
    mf_trimesh_report r;
    if (rc == 0)
        rc = mf_trimesh_check(&m, &r);
    double extent = 0;
    if (rc == 0) {
        for (int a = 0; a < 3; a++)
            extent = fmax(extent, r.max[a] - r.min[a]);
        double centre[3] = {0.5 * (r.min[0] + r.max[0]), 0.5 * (r.min[1] + r.max[1]),
                            0.5 * (r.min[2] + r.max[2])};
        double w = mf_trimesh_winding(&m, centre);
        if (isnan(w) && isfinite(extent))
            abort();
    }
    mf_trimesh_free(&m);
    if (rc != 0 && mf_error_message()[0] == '\0')
        abort();
    mf_error_clear();
    /* Ten lattice points across the mesh: enough to reach every branch of
     * the wall and fill code, few enough for thousands of runs a second. */
    if (rc == 0 && extent > 1e-6 && extent < 1e6) {
        build_scene(path, "walls", extent / 10);
        build_scene(path, "obstacles", extent / 10);
        build_scene(path, "fluidBlocks", extent / 10);
    }
    return 0;
}
