/* mesh_writer.c: surface meshes as binary PLY, OBJ and HDF5, and the XDMF
 * index of a surface time series (mf_mesh_writer.h).
 *
 * PLY (Turk 1994; the format as Blender's importer reads it): an ASCII
 * header (its comments: the time, and that y is up, the case's axes), then
 * little-endian records; vertices as six float32 (position,
 * normal), faces as a uchar count (3) and three int32 indices. */
#include <dirent.h>
#include <errno.h>
#include <hdf5.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_alloc.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_mesh_writer.h"
#include "mf_timetext.h"

#define PATH_MAX_LEN 4352

static bool little_endian(void)
{
    const uint16_t one = 1;
    return *(const uint8_t *)&one == 1;
}

static void put_u32le(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void put_f32le(uint8_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, 4);
    put_u32le(p, v);
}

static uint32_t get_u32le(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float get_f32le(const uint8_t *p)
{
    uint32_t v = get_u32le(p);
    float f;
    memcpy(&f, &v, 4);
    return f;
}

int mf_mesh_write_ply(const char *path, const mf_mesh *m)
{
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "wb"));
    FILE *f = out.f;
    bool ok = fprintf(f,
                      "ply\nformat binary_little_endian 1.0\ncomment mpsflow surface, time "
                      "%.17g\ncomment axes of the case: y is up (Blender, z up: "
                      "mpsflowBlenderImport.py turns it)\nelement vertex %zu\nproperty float x\nproperty float y\nproperty "
                      "float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement "
                      "face %zu\nproperty list uchar int vertex_indices\nend_header\n",
                      m->time, m->nverts, m->ntris) > 0;
    enum { BATCH = 4096 };
    uint8_t buf[BATCH * 24];
    for (size_t v0 = 0; ok && v0 < m->nverts; v0 += BATCH) {
        size_t n = m->nverts - v0 < BATCH ? m->nverts - v0 : BATCH;
        if (little_endian()) {
            for (size_t k = 0; k < n; k++) {
                memcpy(buf + 24 * k, &m->xyz[3 * (v0 + k)], 12);
                memcpy(buf + 24 * k + 12, &m->normal[3 * (v0 + k)], 12);
            }
        } else {
            for (size_t k = 0; k < n; k++)
                for (int a = 0; a < 3; a++) {
                    put_f32le(buf + 24 * k + 4 * a, m->xyz[3 * (v0 + k) + a]);
                    put_f32le(buf + 24 * k + 12 + 4 * a, m->normal[3 * (v0 + k) + a]);
                }
        }
        ok = fwrite(buf, 24, n, f) == n;
    }
    for (size_t t0 = 0; ok && t0 < m->ntris; t0 += BATCH) {
        size_t n = m->ntris - t0 < BATCH ? m->ntris - t0 : BATCH;
        for (size_t k = 0; k < n; k++) {
            uint8_t *p = buf + 13 * k;
            p[0] = 3;
            for (int a = 0; a < 3; a++)
                put_u32le(p + 1 + 4 * a, (uint32_t)m->tri[3 * (t0 + k) + a]);
        }
        ok = fwrite(buf, 13, n, f) == n;
    }
    (void)ok; /* a failed write leaves the stream's error flag: the commit sees it */
    MF_CALL(mf_replace_commit(&out, 0));
    return 0;
}

int mf_mesh_write_obj(const char *path, const mf_mesh *m)
{
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "w"));
    FILE *f = out.f;
    char *big = malloc(1 << 16); /* a large buffer: fprintf per line is the cost */
    if (big)
        setvbuf(f, big, _IOFBF, 1 << 16);
    bool ok = fprintf(f, "# mpsflow surface, time %.17g\n# %zu vertices, %zu triangles\n",
                      m->time, m->nverts, m->ntris) > 0;
    for (size_t v = 0; ok && v < m->nverts; v++)
        ok = fprintf(f, "v %.7g %.7g %.7g\n", m->xyz[3 * v], m->xyz[3 * v + 1],
                     m->xyz[3 * v + 2]) > 0;
    for (size_t v = 0; ok && v < m->nverts; v++)
        ok = fprintf(f, "vn %.6g %.6g %.6g\n", m->normal[3 * v], m->normal[3 * v + 1],
                     m->normal[3 * v + 2]) > 0;
    for (size_t t = 0; ok && t < m->ntris; t++) {
        long a = (long)m->tri[3 * t] + 1, b = (long)m->tri[3 * t + 1] + 1,
             c = (long)m->tri[3 * t + 2] + 1;
        ok = fprintf(f, "f %ld//%ld %ld//%ld %ld//%ld\n", a, a, b, b, c, c) > 0;
    }
    (void)ok;
    int rc = mf_replace_commit(&out, 0); /* before free: the buffer is the stream's */
    free(big);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}

/* ---- HDF5 --------------------------------------------------------------- */

static int h5_dataset(hid_t file, const char *name, hid_t ftype, hid_t mtype, size_t rows,
                      const void *data, const char *path)
{
    hsize_t dims[2] = {rows, 3};
    hid_t space = H5Screate_simple(2, dims, NULL);
    hid_t dset = space >= 0 ? H5Dcreate2(file, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT,
                                         H5P_DEFAULT)
                            : -1;
    herr_t st = dset >= 0 && rows > 0 ? H5Dwrite(dset, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data)
                                      : (dset >= 0 ? 0 : -1);
    if (dset >= 0)
        H5Dclose(dset);
    if (space >= 0)
        H5Sclose(space);
    if (st < 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot write dataset /%s", path, name);
    return 0;
}

int mf_mesh_write_h5(const char *path, const mf_mesh *m)
{
    char tmp[PATH_MAX_LEN];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    H5E_auto2_t func;
    void *cdata;
    H5Eget_auto2(H5E_DEFAULT, &func, &cdata);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    int rc = 0;
    hid_t file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0)
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot create", tmp);
    if (rc == 0)
        rc = h5_dataset(file, "Vertices", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, m->nverts, m->xyz,
                        path);
    if (rc == 0)
        rc = h5_dataset(file, "Normals", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, m->nverts, m->normal,
                        path);
    if (rc == 0)
        rc = h5_dataset(file, "Triangles", H5T_STD_I32LE, H5T_NATIVE_INT32, m->ntris, m->tri,
                        path);
    if (rc == 0) {
        hid_t space = H5Screate(H5S_SCALAR);
        hid_t attr = H5Acreate2(file, "Time", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
        if (attr < 0 || H5Awrite(attr, H5T_NATIVE_DOUBLE, &m->time) < 0)
            rc = MF_ERROR(MF_ERR_IO, "%s: cannot write attribute Time", path);
        if (attr >= 0)
            H5Aclose(attr);
        H5Sclose(space);
    }
    if (file >= 0 && H5Fclose(file) < 0 && rc == 0)
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot close", tmp);
    H5Eset_auto2(H5E_DEFAULT, func, cdata);
    if (rc == 0)
        rc = mf_rename_synced(tmp, path);
    if (rc != 0)
        remove(tmp);
    return rc;
}

/* ---- PLY reader ---------------------------------------------------------- */

int mf_mesh_read_ply(const char *path, mf_mesh *m)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return MF_ERROR(MF_ERR_IO, "%s: cannot open (%s)", path, strerror(errno));
    char line[512];
    size_t nv = 0, nf = 0, nprops = 0;
    int element = 0; /* 1 vertex, 2 face */
    bool binary_le = false, ok_face = false, magic = false;
    int rc = 0;
    while (fgets(line, sizeof line, f)) {
        if (!magic) {
            magic = strncmp(line, "ply", 3) == 0;
            if (!magic)
                break;
            continue;
        }
        if (strncmp(line, "format ", 7) == 0)
            binary_le = strstr(line, "binary_little_endian") != NULL;
        else if (sscanf(line, "element vertex %zu", &nv) == 1)
            element = 1;
        else if (sscanf(line, "element face %zu", &nf) == 1)
            element = 2;
        else if (strncmp(line, "element ", 8) == 0)
            element = 3;
        else if (strncmp(line, "property ", 9) == 0) {
            if (element == 1) {
                if (!strstr(line, "float"))
                    rc = MF_ERROR(MF_ERR_INPUT, "%s: vertex property is not float: %s", path,
                                  line);
                nprops++;
            } else if (element == 2) {
                ok_face = strstr(line, "list uchar int") || strstr(line, "list uchar uint") ||
                          strstr(line, "list uint8 int32");
            } else if (element == 3)
                rc = MF_ERROR(MF_ERR_INPUT, "%s: only vertex and face elements are read", path);
        } else if (strncmp(line, "end_header", 10) == 0)
            break;
    }
    if (rc == 0 && (!magic || !binary_le || !ok_face || (nprops != 3 && nprops != 6)))
        rc = MF_ERROR(MF_ERR_INPUT,
                      "%s: not a binary little-endian PLY with float x y z [nx ny nz] and "
                      "faces 'list uchar int'",
                      path);
    if (rc == 0)
        rc = mf_mesh_reserve(m, nv, nf);
    uint8_t rec[24];
    for (size_t v = 0; rc == 0 && v < nv; v++) {
        if (fread(rec, 4, nprops, f) != nprops) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s: truncated in vertex %zu", path, v);
            break;
        }
        for (int a = 0; a < 3; a++) {
            m->xyz[3 * v + a] = get_f32le(rec + 4 * a);
            m->normal[3 * v + a] = nprops == 6 ? get_f32le(rec + 12 + 4 * a) : 0.0f;
        }
    }
    for (size_t t = 0; rc == 0 && t < nf; t++) {
        if (fread(rec, 13, 1, f) != 1 || rec[0] != 3) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s: face %zu is truncated or not a triangle", path, t);
            break;
        }
        for (int a = 0; a < 3; a++) {
            uint32_t idx = get_u32le(rec + 1 + 4 * a);
            if (idx >= nv) {
                rc = MF_ERROR(MF_ERR_INPUT, "%s: face %zu refers to vertex %u of %zu", path, t,
                              idx, nv);
                break;
            }
            m->tri[3 * t + a] = (int32_t)idx;
        }
    }
    fclose(f);
    if (rc == 0) {
        m->nverts = nv;
        m->ntris = nf;
    }
    return rc;
}

/* ---- the XDMF index ------------------------------------------------------ */

typedef struct frame {
    int index;
    double time;
    long long nverts, ntris;
} frame;

static int by_time(const void *a, const void *b)
{
    const frame *x = a, *y = b;
    if (x->time != y->time)
        return x->time < y->time ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

static bool frame_read(const char *path, frame *fr)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0)
        return false;
    bool ok = false;
    hid_t attr = H5Aopen(file, "Time", H5P_DEFAULT);
    if (attr >= 0) {
        ok = H5Aread(attr, H5T_NATIVE_DOUBLE, &fr->time) >= 0;
        H5Aclose(attr);
    }
    const char *names[2] = {"Vertices", "Triangles"};
    long long *counts[2] = {&fr->nverts, &fr->ntris};
    for (int k = 0; k < 2 && ok; k++) {
        hid_t d = H5Dopen2(file, names[k], H5P_DEFAULT);
        ok = d >= 0;
        if (ok) {
            hid_t s = H5Dget_space(d);
            hsize_t dims[2] = {0, 0};
            ok = s >= 0 && H5Sget_simple_extent_ndims(s) == 2 &&
                 H5Sget_simple_extent_dims(s, dims, NULL) == 2 && dims[1] == 3;
            *counts[k] = (long long)dims[0];
            if (s >= 0)
                H5Sclose(s);
            H5Dclose(d);
        }
    }
    H5Fclose(file);
    return ok;
}

static int scan_frames(const char *dir, const char *prefix, frame **out, size_t *n)
{
    *out = NULL;
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return MF_ERROR(MF_ERR_IO, "%s: cannot open the folder (%s)", dir, strerror(errno));
    size_t cap = 0, plen = strlen(prefix);
    struct dirent *e;
    int rc = 0;
    while (rc == 0 && (e = readdir(d))) {
        const char *name = e->d_name;
        if (strncmp(name, prefix, plen) != 0 || name[plen] != '_')
            continue;
        int idx;
        char tail[8];
        if (sscanf(name + plen + 1, "%d.h%7s", &idx, tail) != 2 || strcmp(tail, "5") != 0)
            continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 64;
            if (mf_resize(out, cap, sizeof **out)) {
                rc = MF_ERROR(MF_ERR_MEMORY, "out of memory listing %s", dir);
                break;
            }
        }
        (*out)[*n].index = idx;
        (*n)++;
    }
    closedir(d);
    return rc;
}

int mf_mesh_last_index(const char *dir, const char *prefix)
{
    frame *fr = NULL;
    size_t n = 0;
    int last = -1;
    if (scan_frames(dir, prefix, &fr, &n) != 0) {
        mf_error_clear();
        return -1;
    }
    for (size_t k = 0; k < n; k++)
        if (fr[k].index > last)
            last = fr[k].index;
    free(fr);
    return last;
}

int mf_mesh_write_xdmf_index(const char *dir, const char *prefix)
{
    frame *fr = NULL;
    size_t n = 0;
    MF_CALL(scan_frames(dir, prefix, &fr, &n));
    H5E_auto2_t func;
    void *cdata;
    H5Eget_auto2(H5E_DEFAULT, &func, &cdata);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    size_t m = 0;
    char path[PATH_MAX_LEN];
    for (size_t k = 0; k < n; k++) {
        snprintf(path, sizeof path, "%s/%s_%06d.h5", dir, prefix, fr[k].index);
        if (frame_read(path, &fr[k]) && fr[k].ntris > 0)
            fr[m++] = fr[k];
    }
    H5Eset_auto2(H5E_DEFAULT, func, cdata);
    qsort(fr, m, sizeof *fr, by_time);
    /* one frame per time: the newest file (highest index) wins */
    size_t u = 0;
    for (size_t k = 0; k < m; k++) {
        if (u > 0 && fr[u - 1].time == fr[k].time)
            fr[u - 1] = fr[k];
        else
            fr[u++] = fr[k];
    }
    char final[PATH_MAX_LEN];
    snprintf(final, sizeof final, "%s/%s.xdmf", dir, prefix);
    mf_replace out;
    int orc = mf_replace_open(&out, final, "w");
    if (orc != 0) {
        free(fr);
        return mf_error_trace(orc, __FILE__, __LINE__, __func__);
    }
    FILE *f = out.f;
    bool ok = fprintf(f,
                      "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
                      "<!-- mpsflow surface meshes: open in ParaView next to "
                      "output/particles.xdmf -->\n"
                      "<Xdmf Version=\"2.0\">\n <Domain>\n  <Grid Name=\"%s\" "
                      "GridType=\"Collection\" CollectionType=\"Temporal\">\n",
                      prefix) > 0;
    for (size_t k = 0; ok && k < u; k++) {
        char file[256], time[32];
        snprintf(file, sizeof file, "%s_%06d.h5", prefix, fr[k].index);
        mf_time_text(fr[k].time, time, sizeof time);
        ok = fprintf(f,
                     "   <Grid Name=\"%s_%06d\" GridType=\"Uniform\">\n"
                     "    <Time Value=\"%s\"/>\n"
                     "    <Topology TopologyType=\"Triangle\" NumberOfElements=\"%lld\">\n"
                     "     <DataItem Dimensions=\"%lld 3\" NumberType=\"Int\" Precision=\"4\" "
                     "Format=\"HDF\">%s:/Triangles</DataItem>\n"
                     "    </Topology>\n"
                     "    <Geometry GeometryType=\"XYZ\">\n"
                     "     <DataItem Dimensions=\"%lld 3\" NumberType=\"Float\" Precision=\"4\" "
                     "Format=\"HDF\">%s:/Vertices</DataItem>\n"
                     "    </Geometry>\n"
                     "    <Attribute Name=\"Normals\" AttributeType=\"Vector\" Center=\"Node\">\n"
                     "     <DataItem Dimensions=\"%lld 3\" NumberType=\"Float\" Precision=\"4\" "
                     "Format=\"HDF\">%s:/Normals</DataItem>\n"
                     "    </Attribute>\n"
                     "   </Grid>\n",
                     prefix, fr[k].index, time, fr[k].ntris, fr[k].ntris, file,
                     fr[k].nverts, file, fr[k].nverts, file) > 0;
    }
    if (ok)
        fprintf(f, "  </Grid>\n </Domain>\n</Xdmf>\n");
    free(fr);
    MF_CALL(mf_replace_commit(&out, 0));
    return 0;
}

int mf_mesh_write_frame(const char *dir, const char *prefix, int index, const mf_mesh *m,
                        bool ply, bool obj)
{
    MF_CALL(mf_mesh_write_frame_files(dir, prefix, index, m, ply, obj));
    MF_CALL(mf_mesh_write_xdmf_index(dir, prefix));
    return 0;
}

int mf_mesh_write_frame_files(const char *dir, const char *prefix, int index, const mf_mesh *m,
                              bool ply, bool obj)
{
    MF_CALL(mf_mkdir_p(dir));
    char path[PATH_MAX_LEN];
    if (ply) {
        snprintf(path, sizeof path, "%s/%s_%06d.ply", dir, prefix, index);
        MF_CALL(mf_mesh_write_ply(path, m));
    }
    if (obj) {
        snprintf(path, sizeof path, "%s/%s_%06d.obj", dir, prefix, index);
        MF_CALL(mf_mesh_write_obj(path, m));
    }
    snprintf(path, sizeof path, "%s/%s_%06d.h5", dir, prefix, index);
    MF_CALL(mf_mesh_write_h5(path, m));
    return 0;
}
