/* mesh_import.c: polygon files through assimp's C API (assimp/cimport.h),
 * loaded on first use (mf_assimp_load.h). */
#include "mf_mesh_import.h"

#include <assimp/scene.h>
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "mf_assimp_load.h"
#include "mf_error.h"

/* Vertices of one assimp mesh, through the node's accumulated transform
 * (a row-major 4x4 affine matrix). */
static int add_mesh(mf_trimesh *out, const struct aiMesh *am, const struct aiMatrix4x4 *t)
{
    size_t base = out->nverts;
    if ((am->mNumVertices && !am->mVertices) || (am->mNumFaces && !am->mFaces))
        return MF_ERROR(MF_ERR_INPUT, "%s: a mesh without its vertex or face arrays", out->name);
    MF_CALL(mf_trimesh_reserve(out, base + am->mNumVertices, out->ntris + am->mNumFaces));
    for (unsigned v = 0; v < am->mNumVertices; v++) {
        const struct aiVector3D *p = &am->mVertices[v];
        double x[3] = {
            t->a1 * p->x + t->a2 * p->y + t->a3 * p->z + t->a4,
            t->b1 * p->x + t->b2 * p->y + t->b3 * p->z + t->b4,
            t->c1 * p->x + t->c2 * p->y + t->c3 * p->z + t->c4,
        };
        for (int a = 0; a < 3; a++)
            if (!isfinite(x[a]))
                return MF_ERROR(MF_ERR_INPUT, "%s: vertex %u has a non-finite coordinate",
                                out->name, v);
        MF_CALL(mf_trimesh_add_vertex(out, x));
    }
    for (unsigned f = 0; f < am->mNumFaces; f++) {
        const struct aiFace *face = &am->mFaces[f];
        if (face->mNumIndices && !face->mIndices)
            return MF_ERROR(MF_ERR_INPUT, "%s: face %u has no indices", out->name, f);
        if (face->mNumIndices < 3) { /* points and lines */
            out->dropped++;
            continue;
        }
        for (unsigned k = 0; k < face->mNumIndices; k++)
            if (face->mIndices[k] >= am->mNumVertices)
                return MF_ERROR(MF_ERR_INPUT, "%s: face %u names vertex %u of %u", out->name, f,
                                face->mIndices[k] + 1, am->mNumVertices);
        /* A polygon as a fan of triangles from its first corner: the faces of
         * the files we read (quads, convex polygons) are split exactly. */
        for (unsigned k = 1; k + 1 < face->mNumIndices; k++)
            MF_CALL(mf_trimesh_add_triangle(out, (int32_t)(base + face->mIndices[0]),
                                            (int32_t)(base + face->mIndices[k]),
                                            (int32_t)(base + face->mIndices[k + 1])));
    }
    return 0;
}

static void mat_mul(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b,
                    struct aiMatrix4x4 *c)
{
    const ai_real *x = &a->a1, *y = &b->a1;
    ai_real r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            ai_real s = 0;
            for (int k = 0; k < 4; k++)
                s += x[4 * i + k] * y[4 * k + j];
            r[4 * i + j] = s;
        }
    memcpy(&c->a1, r, sizeof r);
}

static int add_node(mf_trimesh *out, const struct aiScene *sc, const struct aiNode *node,
                    const struct aiMatrix4x4 *parent, int depth)
{
    if (depth > 64)
        return MF_ERROR(MF_ERR_INPUT, "%s: scene graph nested more than 64 deep", out->name);
    struct aiMatrix4x4 t;
    mat_mul(parent, &node->mTransformation, &t);
    if ((node->mNumMeshes && !node->mMeshes) || (node->mNumChildren && !node->mChildren))
        return MF_ERROR(MF_ERR_INPUT, "%s: a scene node without its arrays", out->name);
    for (unsigned k = 0; k < node->mNumMeshes; k++)
        if (node->mMeshes[k] < sc->mNumMeshes && sc->mMeshes && sc->mMeshes[node->mMeshes[k]])
            MF_CALL(add_mesh(out, sc->mMeshes[node->mMeshes[k]], &t));
    for (unsigned k = 0; k < node->mNumChildren; k++)
        if (node->mChildren[k])
            MF_CALL(add_node(out, sc, node->mChildren[k], &t, depth + 1));
    return 0;
}

/* The formats read: assimp reads dozens, and some of its readers crash on a
 * broken file (its OFF reader read out of bounds on a face list longer than
 * the file, found by fuzzing, and that inside the library, where no check of
 * ours can reach). These three are what polygon geometry for a scene comes
 * in, and the fuzz_mesh harness tries them. */
static const char *const formats[] = {"obj", "stl", "ply"};

static int check_format(const char *path)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (dot && (!slash || dot > slash))
        for (size_t k = 0; k < sizeof formats / sizeof formats[0]; k++)
            if (strcasecmp(dot + 1, formats[k]) == 0)
                return 0;
    return MF_ERROR(MF_ERR_INPUT,
                    "%s: not a polygon format read here (the name must end in .obj, .stl or "
                    ".ply; convert the file, e.g. with meshlab or Blender)",
                    path);
}

int mf_mesh_import(const char *path, mf_trimesh *out)
{
    size_t len = strlen(path) < sizeof out->name - 1 ? strlen(path) : sizeof out->name - 1;
    memcpy(out->name, path, len);
    out->name[len] = '\0';
    MF_CALL(check_format(path));
    struct stat st;
    if (stat(path, &st) != 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot open (%s)", path, strerror(errno));
    /* Only regular files, of a size known before assimp reads a byte: a FIFO
     * would block, a device never end. */
    if (!S_ISREG(st.st_mode))
        return MF_ERROR(MF_ERR_INPUT, "%s: is %s, not a regular file: not a polygon file", path,
                        S_ISDIR(st.st_mode)    ? "a folder"
                        : S_ISFIFO(st.st_mode) ? "a FIFO (named pipe)"
                        : S_ISCHR(st.st_mode)  ? "a character device"
                                               : "a special file");
    if (st.st_size == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: the file is empty (0 bytes)", path);
    if ((uintmax_t)st.st_size > MF_MESH_MAX_FILE_BYTES)
        return MF_ERROR(MF_ERR_INPUT, "%s: %jd bytes is more than the %zu GiB a polygon file may "
                        "have here", path, (intmax_t)st.st_size, MF_MESH_MAX_FILE_BYTES >> 30);
    const char *dot = strrchr(path, '.');
    if (strcasecmp(dot + 1, "ply") == 0)
        MF_CALL(mf_ply_check_header(path, (size_t)st.st_size));
    /* No post-processing: assimp's own triangulation stops the process (an
     * assertion) on some broken files (found by fuzzing: an OFF file with a
     * bad face line). Polygons are split here instead (add_mesh, which also
     * checks every index), corners merged by mf_trimesh_weld; points and
     * lines are counted, and refused by the scene builder. */
    const mf_assimp_api *ai;
    MF_CALL(mf_assimp_load(path, &ai));
    const struct aiScene *sc = ai->import_file(path, 0);
    if (!sc)
        return MF_ERROR(MF_ERR_INPUT, "%s: not a polygon file assimp can read (%s)", path,
                        ai->get_error_string());
    int rc = 0;
    if (sc->mRootNode) {
        struct aiMatrix4x4 id = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        rc = add_node(out, sc, sc->mRootNode, &id, 0);
    }
    ai->release_import(sc);
    MF_CALL(rc);
    if (out->ntris == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: holds no triangle or polygon (%zu vertices, %zu points "
                        "or lines): nothing to make a surface of", path, out->nverts,
                        out->dropped);
    double mn[3], mx[3], extent = 0;
    mf_trimesh_bounds(out, mn, mx);
    for (int a = 0; a < 3; a++)
        extent = fmax(extent, mx[a] - mn[a]);
    return mf_trimesh_weld(out, 1e-9 * extent);
}

static int read_in_case(void *ctx, const char *file, const char *relative_to, mf_trimesh *out)
{
    (void)ctx;
    if (file[0] == '/' || !relative_to)
        return mf_mesh_import(file, out);
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", relative_to);
    char *slash = strrchr(dir, '/');
    if (slash)
        slash[1] = '\0';
    else
        dir[0] = '\0';
    char a[8192], b[8192];
    snprintf(a, sizeof a, "%s%s", dir, file);
    snprintf(b, sizeof b, "%striSurface/%s", dir, file);
    struct stat st;
    if (stat(a, &st) == 0)
        return mf_mesh_import(a, out);
    if (stat(b, &st) == 0)
        return mf_mesh_import(b, out);
    size_t len = strlen(a) < sizeof out->name - 1 ? strlen(a) : sizeof out->name - 1;
    memcpy(out->name, a, len);
    out->name[len] = '\0';
    return MF_ERROR(MF_ERR_IO, "polygon file '%s' not found (looked for %s and %s)", file, a, b);
}

mf_trimesh_reader mf_mesh_import_reader(void)
{
    return (mf_trimesh_reader){read_in_case, NULL};
}
