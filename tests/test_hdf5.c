/* test_hdf5.c: HDF5 snapshots, restart and the XDMF index.
 *
 * Particles of all five kinds, interleaved in storage and with gaps in
 * their ids, carry double, int32 and vector fields (one not for output).
 * Two snapshots are written through the writer module; a fresh run reads
 * the newest back and must hold bit-identical arrays in the same order.
 * Then the edges: the XDMF index against the files, a leftover .tmp, no
 * snapshot at all, truncated and inconsistent files, NaN coordinates. */
#include <hdf5.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mf_dict.h"
#include "mf_hdf5.h"
#include "mf_params.h"
#include "mf_particles.h"
#include "mf_sim.h"
#include "mf_test.h"

#define NPART 157

/* ---- helpers ----------------------------------------------------------- */

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

/* Doubles with all 53 mantissa bits in use: any rounding would show. */
static double rnd(void)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng_state >> 11) * 0x1.0p-53 - 0.5;
}

static void path_join(char *buf, size_t len, const char *dir, const char *name)
{
    snprintf(buf, len, "%s/%s", dir, name);
}

static bool file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)size + 1);
    if (text && fread(text, 1, (size_t)size, f) != (size_t)size) {
        free(text);
        text = NULL;
    }
    if (text)
        text[size] = '\0';
    fclose(f);
    return text;
}

/* Copy the first `bytes` bytes of src (all when bytes < 0). */
static void copy_file(const char *src, const char *dst, long bytes)
{
    FILE *in = fopen(src, "rb"), *out = fopen(dst, "wb");
    CHECK(in && out);
    if (in && out) {
        char buf[4096];
        long done = 0;
        size_t got;
        while ((bytes < 0 || done < bytes) && (got = fread(buf, 1, sizeof buf, in)) > 0) {
            if (bytes >= 0 && done + (long)got > bytes)
                got = (size_t)(bytes - done);
            fwrite(buf, 1, got, out);
            done += (long)got;
        }
    }
    if (in)
        fclose(in);
    if (out)
        fclose(out);
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

/* MF_TEST_KEEP=1 keeps the temporary cases for a look with h5dump/ParaView. */
static void remove_tree(const char *dir)
{
    if (getenv("MF_TEST_KEEP"))
        return;
    char cmd[4300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

/* No HDF5 object of any file may stay open after our calls. */
static void check_no_open_handles(const char *where)
{
    ssize_t open_objects = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL);
    CHECK_MSG(open_objects == 0, "%s: %zd HDF5 objects left open", where, open_objects);
}

/* The fields every run of this test requests (same as a solver would). */
typedef struct fields {
    int pressure, density, fluid_id, normal, scratch;
} fields;

static void request_fields(mf_particles *p, fields *f)
{
    /* Requested in a different order than the file lists them (by name). */
    CHECK_OK(mf_particles_request_field(p, "Pressure", 1, MF_FIELD_DOUBLE, true, &f->pressure));
    CHECK_OK(mf_particles_request_field(p, "Normal", 3, MF_FIELD_DOUBLE, true, &f->normal));
    CHECK_OK(mf_particles_request_field(p, "FluidId", 1, MF_FIELD_INT32, true, &f->fluid_id));
    CHECK_OK(mf_particles_request_field(p, "Scratch", 1, MF_FIELD_DOUBLE, false, &f->scratch));
    CHECK_OK(mf_particles_request_field(p, "NumberDensity", 1, MF_FIELD_DOUBLE, true,
                                        &f->density));
}

/* Particles of all kinds, interleaved; some removed so ids have gaps. */
static mf_particles *build_particles(int dim, fields *f)
{
    mf_particles *p = NULL;
    CHECK_OK(mf_particles_create(dim, 16, &p));
    if (!p)
        return NULL;
    request_fields(p, f);
    for (int i = 0; i < NPART + 20; i++) {
        double x[3] = {rnd(), rnd(), dim == 3 ? rnd() : 0.0};
        double v[3] = {rnd(), rnd(), dim == 3 ? rnd() : 0.0};
        int kind = (i * 7 + i / 3) % MF_NKINDS;
        CHECK_OK(mf_particles_add(p, kind, x, v, NULL));
    }
    uint8_t flag[NPART + 20] = {0};
    for (int i = 3; i < NPART + 20; i += 9)
        flag[i] = 1;
    size_t removed = 0;
    CHECK_OK(mf_particles_remove(p, flag, &removed));
    for (size_t i = 0; i < p->n; i++) {
        mf_particles_fd(p, f->pressure)[i] = 1e5 * rnd();
        mf_particles_fd(p, f->density)[i] = 6.0 + rnd();
        mf_particles_fi(p, f->fluid_id)[i] = (int32_t)(i % 3) - 1;
        mf_particles_fd(p, f->scratch)[i] = 42.0;
        for (int d = 0; d < 3; d++)
            mf_particles_fd(p, f->normal)[3 * i + d] = rnd();
    }
    return p;
}

static mf_dict *build_params(void)
{
    mf_dict *d = mf_dict_new("", NULL);
    CHECK(d != NULL);
    if (!d)
        return NULL;
    CHECK_OK(mf_dict_set_number(d, "endTime", 1.5));
    CHECK_OK(mf_dict_set_number(d, "deltaT", 0.1));
    CHECK_OK(mf_dict_set_word(d, "solver", "mps"));
    mf_dict *sub = mf_dict_set_subdict(d, "mps");
    CHECK(sub != NULL);
    if (sub) {
        double g[3] = {0, -9.81, 0};
        CHECK_OK(mf_dict_set_vector(sub, "gravity", g));
        CHECK_OK(mf_dict_set_number(sub, "relaxation", 0.2));
    }
    return d;
}

static bool same_bytes(const void *a, const void *b, size_t bytes)
{
    return bytes == 0 || memcmp(a, b, bytes) == 0;
}

/* Every stored array of b equals a's, bit for bit, in the same order. */
static void check_same_particles(const mf_particles *a, const fields *fa, const mf_particles *b,
                                 const fields *fb)
{
    CHECK(b->n == a->n_owned && b->n_owned == a->n_owned);
    CHECK(b->next_id == a->next_id);
    CHECK(b->dim == a->dim);
    size_t n = a->n_owned < b->n ? a->n_owned : b->n;
    CHECK(same_bytes(a->pos, b->pos, 3 * n * sizeof(double)));
    CHECK(same_bytes(a->vel, b->vel, 3 * n * sizeof(double)));
    CHECK(same_bytes(a->kind, b->kind, n));
    CHECK(same_bytes(a->id, b->id, n * sizeof(int64_t)));
    CHECK(same_bytes(mf_particles_fd(a, fa->pressure), mf_particles_fd(b, fb->pressure),
                     n * sizeof(double)));
    CHECK(same_bytes(mf_particles_fd(a, fa->density), mf_particles_fd(b, fb->density),
                     n * sizeof(double)));
    CHECK(same_bytes(mf_particles_fi(a, fa->fluid_id), mf_particles_fi(b, fb->fluid_id),
                     n * sizeof(int32_t)));
    CHECK(same_bytes(mf_particles_fd(a, fa->normal), mf_particles_fd(b, fb->normal),
                     3 * n * sizeof(double)));
    /* Not written, so it restarts from zero. */
    bool scratch_zero = true;
    for (size_t i = 0; i < n; i++)
        scratch_zero = scratch_zero && mf_particles_fd(b, fb->scratch)[i] == 0.0;
    CHECK(scratch_zero);
}

/* ---- file content ------------------------------------------------------ */

static bool h5_has(hid_t file, const char *path)
{
    /* Each level must exist before H5Lexists may look below it. */
    char part[256];
    for (const char *s = strchr(path + 1, '/');; s = strchr(s + 1, '/')) {
        size_t len = s ? (size_t)(s - path) : strlen(path);
        snprintf(part, sizeof part, "%.*s", (int)len, path);
        if (H5Lexists(file, part, H5P_DEFAULT) <= 0)
            return false;
        if (!s)
            return true;
    }
}

static void read_string_attr(hid_t obj, const char *name, char *buf, size_t len)
{
    buf[0] = '\0';
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    CHECK_MSG(attr >= 0, "attribute %s", name);
    if (attr < 0)
        return;
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, len);
    CHECK(H5Aread(attr, type, buf) >= 0);
    buf[len - 1] = '\0';
    H5Tclose(type);
    H5Aclose(attr);
}

static void check_file_content(const char *path, int dim)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    CHECK_MSG(file >= 0, "open %s", path);
    if (file < 0)
        return;
    for (int k = 0; k < MF_NKINDS; k++) {
        char name[64];
        snprintf(name, sizeof name, "/PartType%d/Pressure", k);
        CHECK_MSG(h5_has(file, name), "%s", name);
        snprintf(name, sizeof name, "/PartType%d/StorageIndex", k);
        CHECK_MSG(h5_has(file, name), "%s", name);
        snprintf(name, sizeof name, "/PartType%d/Scratch", k);
        CHECK_MSG(!h5_has(file, name), "output=false field written: %s", name);
    }
    char text[64];
    hid_t g = H5Gopen2(file, "/PartType0", H5P_DEFAULT);
    read_string_attr(g, "KindName", text, sizeof text);
    CHECK(strcmp(text, "fluid") == 0);
    H5Gclose(g);
    g = H5Gopen2(file, "/PartType4", H5P_DEFAULT);
    read_string_attr(g, "KindName", text, sizeof text);
    CHECK(strcmp(text, "outlet") == 0);
    H5Gclose(g);
    hid_t d = H5Dopen2(file, "/PartType0/Pressure", H5P_DEFAULT);
    read_string_attr(d, "Units", text, sizeof text);
    CHECK(strcmp(text, "Pa") == 0);
    H5Dclose(d);
    d = H5Dopen2(file, "/PartType2/Velocities", H5P_DEFAULT);
    read_string_attr(d, "Units", text, sizeof text);
    CHECK(strcmp(text, "m/s") == 0);
    H5Dclose(d);

    g = H5Gopen2(file, "/Header", H5P_DEFAULT);
    read_string_attr(g, "Code", text, sizeof text);
    CHECK(strcmp(text, "mpsflow") == 0);
    read_string_attr(g, "CodeVersion", text, sizeof text);
    CHECK(strcmp(text, MPSFLOW_VERSION) == 0);
    H5Gclose(g);
    mf_hdf5_header h;
    CHECK_OK(mf_hdf5_read_header(path, &h));
    CHECK(h.dim == dim);

    CHECK(h5_has(file, "/Parameters/mps"));
    g = H5Gopen2(file, "/Parameters", H5P_DEFAULT);
    read_string_attr(g, "endTime", text, sizeof text);
    CHECK_MSG(strcmp(text, "1.5") == 0, "endTime = '%s'", text);
    read_string_attr(g, "solver", text, sizeof text);
    CHECK(strcmp(text, "mps") == 0);
    H5Gclose(g);
    g = H5Gopen2(file, "/Parameters/mps", H5P_DEFAULT);
    read_string_attr(g, "gravity", text, sizeof text);
    CHECK_MSG(strcmp(text, "(0 -9.81 0)") == 0, "gravity = '%s'", text);
    read_string_attr(g, "relaxation", text, sizeof text);
    CHECK_MSG(strcmp(text, "0.20000000000000001") != 0 && strtod(text, NULL) == 0.2,
              "relaxation = '%s'", text);
    H5Gclose(g);
    H5Fclose(file);
}

/* The file is a closed, whole HDF5 file: opened read-only in memory, its
 * image (H5Fget_file_image) must be the file byte for byte, so it ends where
 * HDF5's allocation ends (nothing cut, nothing after) and its superblock's
 * consistency flags (bytes 20-23 of a version 0 superblock, set while the
 * writer has the file open) are cleared, as HDF5's close leaves them. The
 * writer used to build the image itself and had to clear them; now HDF5
 * writes the file (sec2) and this checks that the close happened. That the
 * file reads in a fresh process: check_h5dump. */
static void check_image(const char *path)
{
    char *bytes = NULL;
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    if (!f)
        return;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    bytes = size > 24 ? malloc((size_t)size) : NULL;
    CHECK(bytes && fread(bytes, 1, (size_t)size, f) == (size_t)size);
    fclose(f);
    if (!bytes)
        return;
    CHECK(bytes[8] == 0); /* superblock version 0 */
    CHECK(bytes[20] == 0 && bytes[21] == 0 && bytes[22] == 0 && bytes[23] == 0);
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    CHECK(fapl >= 0 && H5Pset_fapl_core(fapl, (size_t)1 << 20, 0) >= 0);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    CHECK(file >= 0);
    ssize_t n = file >= 0 ? H5Fget_file_image(file, NULL, 0) : -1;
    CHECK(n == size);
    char *image = n == size ? malloc((size_t)n) : NULL;
    CHECK(image && H5Fget_file_image(file, image, (size_t)n) == n &&
          memcmp(image, bytes, (size_t)n) == 0);
    free(image);
    free(bytes);
    if (file >= 0)
        H5Fclose(file);
    H5Pclose(fapl);
}

static void check_h5dump(const char *path)
{
    if (access("/usr/bin/h5dump", X_OK) != 0) {
        printf("note: /usr/bin/h5dump not found, h5dump check skipped\n");
        return;
    }
    char cmd[4300];
    snprintf(cmd, sizeof cmd, "/usr/bin/h5dump -H '%s' > /dev/null", path);
    CHECK_MSG(system(cmd) == 0, "h5dump -H %s", path);
}

/* Every DataItem of the index points at a dataset with the stated shape. */
static void check_xdmf(const char *output_dir, int nsnapshots)
{
    char path[4200];
    path_join(path, sizeof path, output_dir, "particles.xdmf");
    char *text = read_text(path);
    CHECK_MSG(text != NULL, "read %s", path);
    if (!text)
        return;
    CHECK(strstr(text, "<Xdmf Version=\"2.0\">") != NULL);
    CHECK(strstr(text, "</Xdmf>\n") != NULL);
    int ntimes = 0, nopen = 0, nclose = 0;
    for (const char *s = text; (s = strstr(s, "<Time ")) != NULL; s++)
        ntimes++;
    for (const char *s = text; (s = strstr(s, "<Grid ")) != NULL; s++)
        nopen++;
    for (const char *s = text; (s = strstr(s, "</Grid>")) != NULL; s++)
        nclose++;
    CHECK_MSG(ntimes == nsnapshots, "%d times, expected %d", ntimes, nsnapshots);
    CHECK(nopen == nclose && nopen == 1 + nsnapshots * (1 + MF_NKINDS));
    for (int k = 0; k < nsnapshots; k++) {
        char name[64];
        snprintf(name, sizeof name, "snapshot_%06d.h5:/PartType0/Coordinates", k);
        CHECK_MSG(strstr(text, name) != NULL, "index lists %s", name);
    }
    CHECK(strstr(text, "StorageIndex") == NULL);
    CHECK(strstr(text, "Name=\"Velocities [m/s]\" AttributeType=\"Vector\"") != NULL);
    CHECK(strstr(text, "Name=\"Pressure [Pa]\" AttributeType=\"Scalar\"") != NULL);
    /* Vertex cells for the Xdmf3 readers; Kind shown, PointIndex not. */
    CHECK(strstr(text, "NodesPerElement=\"1\"") != NULL);
    CHECK(strstr(text, ":/PartType0/PointIndex</DataItem>\n        </Topology>") != NULL);
    CHECK(strstr(text, "<Attribute Name=\"PointIndex\"") == NULL);
    CHECK(strstr(text, "Name=\"Kind\" AttributeType=\"Scalar\"") != NULL);
    CHECK(strstr(text, "NumberType=\"UChar\" Precision=\"1\"") != NULL);

    int nitems = 0;
    for (const char *s = text; (s = strstr(s, "<DataItem Dimensions=\"")) != NULL;) {
        s += strlen("<DataItem Dimensions=\"");
        long long dims[2] = {0, 0};
        int rank = sscanf(s, "%lld %lld", &dims[0], &dims[1]);
        const char *quote = strchr(s, '"');
        if (quote && memchr(s, ' ', (size_t)(quote - s)) == NULL)
            rank = 1;
        const char *body = strchr(s, '>');
        const char *end = body ? strchr(body, '<') : NULL;
        CHECK(body && end);
        if (!body || !end)
            break;
        char ref[512];
        snprintf(ref, sizeof ref, "%.*s", (int)(end - body - 1), body + 1);
        char *colon = strchr(ref, ':');
        CHECK_MSG(colon != NULL, "DataItem '%s'", ref);
        if (!colon)
            break;
        *colon = '\0';
        char h5path[4200];
        path_join(h5path, sizeof h5path, output_dir, ref);
        hid_t file = H5Fopen(h5path, H5F_ACC_RDONLY, H5P_DEFAULT);
        hid_t dset = file >= 0 ? H5Dopen2(file, colon + 1, H5P_DEFAULT) : -1;
        CHECK_MSG(dset >= 0, "%s:%s exists", ref, colon + 1);
        if (dset >= 0) {
            hid_t space = H5Dget_space(dset);
            hsize_t hd[2] = {0, 0};
            int hrank = H5Sget_simple_extent_dims(space, hd, NULL);
            CHECK_MSG(hrank == rank && (long long)hd[0] == dims[0] &&
                          (rank == 1 || (long long)hd[1] == dims[1]),
                      "%s:%s is %d-D %llu x %llu, index says %lld x %lld", ref, colon + 1,
                      hrank, (unsigned long long)hd[0], (unsigned long long)hd[1], dims[0],
                      dims[1]);
            H5Sclose(space);
            H5Dclose(dset);
        }
        if (file >= 0)
            H5Fclose(file);
        nitems++;
        s = end;
    }
    CHECK(nitems > 0);
    if (access("/usr/bin/xmllint", X_OK) == 0) {
        char cmd[4300];
        snprintf(cmd, sizeof cmd, "/usr/bin/xmllint --noout '%s'", path);
        CHECK_MSG(system(cmd) == 0, "xmllint %s", path);
    }
    free(text);
}

/* ---- scenarios ----------------------------------------------------------- */

static void make_case(char *dir, size_t len)
{
    snprintf(dir, len, "/tmp/mf_test_hdf5_XXXXXX");
    CHECK(mkdtemp(dir) != NULL);
}

/* Write two snapshots, restart from the newest into fresh particles. */
static void test_roundtrip(int dim, long compression)
{
    char case_dir[256], output_dir[300], path[4200];
    make_case(case_dir, sizeof case_dir);
    snprintf(output_dir, sizeof output_dir, "%s/output", case_dir);
    printf("round trip %d-D, compression %ld in %s\n", dim, compression, case_dir);

    fields fa;
    mf_particles *p = build_particles(dim, &fa);
    mf_dict *params = build_params();
    if (!p || !params)
        return;
    mf_sim sim = {.dim = dim, .l0 = 0.01, .p = p, .time = 0.1, .dt = 1e-3, .step = 100};

    /* Settings the way the host fills them: from the parameter table. */
    const mf_module_info *info = &mf_writer_hdf5.info;
    void *settings = calloc(1, info->settings_size);
    mf_dict *writer_dict = mf_dict_new("hdf5", NULL);
    CHECK(settings && writer_dict);
    if (!settings || !writer_dict)
        return;
    CHECK_OK(mf_dict_set_number(writer_dict, "compression", (double)compression));
    CHECK_OK(mf_params_apply(info->params, info->nparams, writer_dict, NULL, settings, NULL));
    mf_dict_free(writer_dict);
    void *writer = NULL;
    CHECK_OK(mf_writer_hdf5.create(settings, case_dir, &writer));
    if (!writer)
        return;
    CHECK_OK(mf_writer_hdf5.write(writer, &sim, params));
    /* Advance: the second snapshot must be the one restored. */
    for (size_t i = 0; i < 3 * p->n; i++)
        p->vel[i] += 0.25 * rnd();
    mf_particles_fd(p, fa.pressure)[5] = -1.0 / 3.0;
    sim.time = 0.2;
    sim.dt = 7e-4;
    sim.step = 243;
    p->next_id += 5; /* ids handed out to particles that have left */
    CHECK_OK(mf_writer_hdf5.write(writer, &sim, params));
    mf_writer_hdf5.destroy(writer);
    check_no_open_handles("after writing");

    path_join(path, sizeof path, output_dir, "snapshot_000001.h5");
    CHECK(file_exists(path));
    check_file_content(path, dim);
    check_h5dump(path);
    check_image(path);
    check_xdmf(output_dir, 2);
    check_no_open_handles("after checking the files");

    /* A crashed later write left a .tmp: ignored by the reader. */
    path_join(path, sizeof path, output_dir, "snapshot_000002.h5.tmp");
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs("half a snapshot", f);
        fclose(f);
    }

    /* Restart: a new writer and fresh particles with the same requests,
     * plus a field the old run did not have. */
    fields fb;
    mf_particles *q = NULL;
    CHECK_OK(mf_particles_create(dim, 4, &q));
    request_fields(q, &fb);
    int extra;
    CHECK_OK(mf_particles_request_field(q, "Extra", 2, MF_FIELD_DOUBLE, true, &extra));
    mf_sim sim2 = {.dim = dim, .l0 = 0.01, .p = q};
    CHECK_OK(mf_writer_hdf5.create(settings, case_dir, &writer));
    CHECK(mf_writer_hdf5.read_latest != NULL);
    CHECK_OK(mf_writer_hdf5.read_latest(writer, &sim2));
    CHECK(sim2.time == 0.2 && sim2.dt == 7e-4 && sim2.step == 243);
    check_same_particles(p, &fa, q, &fb);
    bool extra_zero = true;
    for (size_t i = 0; i < 2 * q->n; i++)
        extra_zero = extra_zero && mf_particles_fd(q, extra)[i] == 0.0;
    CHECK(extra_zero);

    /* The next write continues the numbering and overwrites the .tmp. */
    sim2.time = 0.3;
    sim2.step = 300;
    CHECK_OK(mf_writer_hdf5.write(writer, &sim2, NULL));
    mf_writer_hdf5.destroy(writer);
    path_join(path, sizeof path, output_dir, "snapshot_000002.h5");
    CHECK(file_exists(path));
    CHECK(!file_exists(strcat(path, ".tmp")));
    check_xdmf(output_dir, 3);
    int index = -1;
    CHECK_OK(mf_hdf5_latest_snapshot(case_dir, path, sizeof path, &index));
    CHECK(index == 2);

    /* Tools: read into no particles at all; every stored field comes back. */
    mf_sim sim3 = {0};
    path_join(path, sizeof path, output_dir, "snapshot_000001.h5");
    CHECK_OK(mf_hdf5_read_snapshot(path, &sim3));
    CHECK(sim3.p && sim3.dim == dim && sim3.l0 == 0.01 && sim3.step == 243);
    if (sim3.p) {
        fields fc;
        fc.pressure = mf_particles_field_index(sim3.p, "Pressure");
        fc.density = mf_particles_field_index(sim3.p, "NumberDensity");
        fc.fluid_id = mf_particles_field_index(sim3.p, "FluidId");
        fc.normal = mf_particles_field_index(sim3.p, "Normal");
        CHECK(fc.pressure >= 0 && fc.density >= 0 && fc.fluid_id >= 0 && fc.normal >= 0);
        CHECK(mf_particles_field_index(sim3.p, "Scratch") < 0);
        CHECK(sim3.p->field[fc.fluid_id].type == MF_FIELD_INT32);
        /* Scratch is absent here: request a zero one to compare. */
        CHECK_OK(mf_particles_request_field(sim3.p, "Scratch", 1, MF_FIELD_DOUBLE, false,
                                            &fc.scratch));
        if (fc.pressure >= 0 && fc.density >= 0 && fc.fluid_id >= 0 && fc.normal >= 0)
            check_same_particles(p, &fa, sim3.p, &fc);
        mf_particles_destroy(sim3.p);
    }

    /* A field requested with another shape than stored: clean error. */
    mf_particles *r = NULL;
    CHECK_OK(mf_particles_create(dim, 4, &r));
    int wrong;
    CHECK_OK(mf_particles_request_field(r, "Pressure", 3, MF_FIELD_DOUBLE, true, &wrong));
    mf_sim sim4 = {.dim = dim, .p = r};
    int rc = mf_hdf5_read_snapshot(path, &sim4);
    CHECK(rc == MF_ERR_INPUT);
    CHECK_MSG(strstr(mf_error_message(), "Pressure") && strstr(mf_error_message(), path),
              "message: %s", mf_error_message());
    mf_error_clear();
    /* The other dimension: refused. */
    mf_sim sim5 = {.dim = 5 - dim, .p = NULL};
    CHECK(mf_hdf5_read_snapshot(path, &sim5) == MF_ERR_INPUT && sim5.p == NULL);
    mf_error_clear();
    mf_particles_destroy(r);
    check_no_open_handles("after reading");

    mf_particles_destroy(p);
    mf_particles_destroy(q);
    mf_dict_free(params);
    free(settings);
    remove_tree(case_dir);
}

static void test_no_snapshot(void)
{
    char case_dir[256];
    make_case(case_dir, sizeof case_dir);
    void *writer = NULL;
    CHECK_OK(mf_writer_hdf5.create(NULL, case_dir, &writer));
    char output_dir[300];
    snprintf(output_dir, sizeof output_dir, "%s/output", case_dir);
    CHECK(file_exists(output_dir));
    mf_sim sim = {.dim = 2};
    int rc = mf_writer_hdf5.read_latest(writer, &sim);
    CHECK(rc == MF_ERR_INPUT);
    CHECK_MSG(strstr(mf_error_message(), "-latestTime") != NULL &&
                  strstr(mf_error_message(), output_dir) != NULL,
              "message: %s", mf_error_message());
    mf_error_clear();
    CHECK(mf_hdf5_latest_snapshot(case_dir, NULL, 0, NULL) == MF_ERR_INPUT);
    mf_error_clear();
    mf_writer_hdf5.destroy(writer);
    /* A case folder that does not exist: create fails cleanly. */
    char missing[300];
    snprintf(missing, sizeof missing, "%s/no/such/case", case_dir);
    writer = NULL;
    CHECK(mf_writer_hdf5.create(NULL, missing, &writer) == MF_ERR_IO && writer == NULL);
    mf_error_clear();
    remove_tree(case_dir);
}

/* Truncated and inconsistent files give clean errors; a corrupt newest
 * snapshot is skipped by the restart. */
static void test_corrupt(void)
{
    char case_dir[256], output_dir[300], good[4200], bad[4200], path[4200];
    make_case(case_dir, sizeof case_dir);
    snprintf(output_dir, sizeof output_dir, "%s/output", case_dir);
    fields fa;
    mf_particles *p = build_particles(3, &fa);
    if (!p)
        return;
    mf_sim sim = {.dim = 3, .l0 = 0.02, .p = p, .time = 1.0, .dt = 1e-3, .step = 7};
    void *writer = NULL;
    CHECK_OK(mf_writer_hdf5.create(NULL, case_dir, &writer));
    CHECK_OK(mf_writer_hdf5.write(writer, &sim, NULL));
    mf_writer_hdf5.destroy(writer);
    path_join(good, sizeof good, output_dir, "snapshot_000000.h5");

    long size = file_size(good);
    CHECK(size > 1000);
    long cuts[] = {0, 8, 100, size / 3, size / 2, size - 16, size - 1};
    for (size_t k = 0; k < sizeof cuts / sizeof cuts[0]; k++) {
        snprintf(bad, sizeof bad, "%s/truncated.h5", case_dir);
        copy_file(good, bad, cuts[k]);
        fields fb;
        mf_particles *q = NULL;
        CHECK_OK(mf_particles_create(3, 4, &q));
        request_fields(q, &fb);
        mf_sim sim2 = {.dim = 3, .p = q};
        int rc = mf_hdf5_read_snapshot(bad, &sim2);
        CHECK_MSG(rc < 0, "truncated to %ld of %ld bytes: rc %d", cuts[k], size, rc);
        CHECK_MSG(strstr(mf_error_message(), "truncated.h5") != NULL, "message: %s",
                  mf_error_message());
        mf_error_clear();
        mf_particles_destroy(q);
        /* The same into no particles: whatever was created is freed. */
        mf_sim sim3 = {0};
        CHECK(mf_hdf5_read_snapshot(bad, &sim3) < 0 && sim3.p == NULL);
        mf_error_clear();
        check_no_open_handles("after a truncated file");
    }

    /* A corrupt newest snapshot: the restart falls back to the one before. */
    path_join(path, sizeof path, output_dir, "snapshot_000001.h5");
    copy_file(good, path, size / 2);
    fields fb;
    mf_particles *q = NULL;
    CHECK_OK(mf_particles_create(3, 4, &q));
    request_fields(q, &fb);
    mf_sim sim2 = {.dim = 3, .p = q};
    CHECK_OK(mf_writer_hdf5.create(NULL, case_dir, &writer));
    CHECK_OK(mf_writer_hdf5.read_latest(writer, &sim2));
    CHECK(sim2.time == 1.0 && sim2.step == 7);
    check_same_particles(p, &fa, q, &fb);
    /* ... and the next snapshot does not overwrite the corrupt one. */
    CHECK_OK(mf_writer_hdf5.write(writer, &sim2, NULL));
    mf_writer_hdf5.destroy(writer);
    path_join(path, sizeof path, output_dir, "snapshot_000002.h5");
    CHECK(file_exists(path));
    CHECK(file_size(good) == size);
    {
        char xdmf[4200];
        path_join(xdmf, sizeof xdmf, output_dir, "particles.xdmf");
        char *text = read_text(xdmf);
        CHECK(text && strstr(text, "snapshot_000002.h5") && !strstr(text, "snapshot_000001.h5"));
        free(text);
    }

    /* Header counts that disagree with the datasets. */
    snprintf(bad, sizeof bad, "%s/inconsistent.h5", case_dir);
    copy_file(good, bad, -1);
    hid_t file = H5Fopen(bad, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t g = H5Gopen2(file, "/Header", H5P_DEFAULT);
    hid_t attr = H5Aopen(g, "NumPart_ThisFile", H5P_DEFAULT);
    int64_t counts[MF_NKINDS];
    CHECK(H5Aread(attr, H5T_NATIVE_INT64, counts) >= 0);
    counts[1] += 1;
    CHECK(H5Awrite(attr, H5T_NATIVE_INT64, counts) >= 0);
    H5Aclose(attr);
    H5Gclose(g);
    H5Fclose(file);
    sim2.p = q;
    int rc = mf_hdf5_read_snapshot(bad, &sim2);
    CHECK(rc == MF_ERR_INPUT);
    CHECK_MSG(strstr(mf_error_message(), "inconsistent.h5") != NULL, "message: %s",
              mf_error_message());
    mf_error_clear();

    /* A dataset missing. */
    copy_file(good, bad, -1);
    file = H5Fopen(bad, H5F_ACC_RDWR, H5P_DEFAULT);
    CHECK(H5Ldelete(file, "/PartType3/Velocities", H5P_DEFAULT) >= 0);
    H5Fclose(file);
    rc = mf_hdf5_read_snapshot(bad, &sim2);
    CHECK(rc == MF_ERR_INPUT);
    CHECK_MSG(strstr(mf_error_message(), "/PartType3/Velocities") != NULL, "message: %s",
              mf_error_message());
    mf_error_clear();
    /* Fails after creating particles for a tool: they are freed again. */
    mf_sim sim3 = {0};
    CHECK(mf_hdf5_read_snapshot(bad, &sim3) == MF_ERR_INPUT && sim3.p == NULL);
    mf_error_clear();

    /* NaN in the coordinates. */
    p->pos[3 * 10 + 1] = 0.0 / 0.0;
    snprintf(bad, sizeof bad, "%s/nan.h5", case_dir);
    CHECK_OK(mf_hdf5_write_snapshot(bad, &sim, NULL, 0));
    rc = mf_hdf5_read_snapshot(bad, &sim2);
    CHECK(rc == MF_ERR_INPUT);
    CHECK_MSG(strstr(mf_error_message(), "nan.h5") && strstr(mf_error_message(), "Coordinates"),
              "message: %s", mf_error_message());
    mf_error_clear();
    check_no_open_handles("after the corrupt files");

    mf_particles_destroy(p);
    mf_particles_destroy(q);
    remove_tree(case_dir);
}

/* An older, longer run's snapshots stay on disk, but the index shows only
 * the current run (times must increase in ParaView). */
static void test_xdmf_lineage(void)
{
    char case_dir[256], output_dir[300];
    make_case(case_dir, sizeof case_dir);
    snprintf(output_dir, sizeof output_dir, "%s/output", case_dir);
    fields fa;
    mf_particles *p = build_particles(2, &fa);
    if (!p)
        return;
    mf_sim sim = {.dim = 2, .l0 = 0.02, .p = p};
    void *writer = NULL;
    CHECK_OK(mf_writer_hdf5.create(NULL, case_dir, &writer));
    for (int k = 0; k < 3; k++) {
        sim.time = 0.5 * k;
        CHECK_OK(mf_writer_hdf5.write(writer, &sim, NULL));
    }
    mf_writer_hdf5.destroy(writer);
    /* A new run from time 0 in the same case. */
    CHECK_OK(mf_writer_hdf5.create(NULL, case_dir, &writer));
    for (int k = 0; k < 2; k++) {
        sim.time = 0.25 * k;
        CHECK_OK(mf_writer_hdf5.write(writer, &sim, NULL));
    }
    mf_writer_hdf5.destroy(writer);
    char xdmf[4200];
    path_join(xdmf, sizeof xdmf, output_dir, "particles.xdmf");
    char *text = read_text(xdmf);
    CHECK(text != NULL);
    if (text) {
        CHECK(strstr(text, "snapshot_000003.h5") && strstr(text, "snapshot_000004.h5"));
        CHECK(!strstr(text, "snapshot_000000.h5") && !strstr(text, "snapshot_000002.h5"));
        free(text);
    }
    /* Rebuilt from the folder alone, the same. */
    remove(xdmf);
    CHECK_OK(mf_hdf5_write_xdmf_index(output_dir));
    text = read_text(xdmf);
    CHECK(text && strstr(text, "snapshot_000004.h5") && !strstr(text, "snapshot_000001.h5"));
    free(text);
    check_no_open_handles("after the index");
    mf_particles_destroy(p);
    remove_tree(case_dir);
}

static void test_module_table(void)
{
    const mf_module_info *info = &mf_writer_hdf5.info;
    CHECK(info->abi_version == MF_ABI_VERSION);
    CHECK(info->kind == MF_KIND_WRITER);
    CHECK(strcmp(info->name, "hdf5") == 0);
    CHECK(info->nparams == 1 && strcmp(info->params[0].name, "compression") == 0);
    CHECK(info->settings_size >= sizeof(long));
    CHECK(mf_writer_hdf5.create && mf_writer_hdf5.write && mf_writer_hdf5.destroy &&
          mf_writer_hdf5.read_latest);
}

int main(void)
{
    test_module_table();
    test_roundtrip(2, 0);
    test_roundtrip(3, 4);
    test_no_snapshot();
    test_corrupt();
    test_xdmf_lineage();
    return mf_test_summary("hdf5");
}
