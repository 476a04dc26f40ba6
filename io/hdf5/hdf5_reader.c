/* hdf5_reader.c: read a snapshot's header, or the whole snapshot back into
 * a run (restart) or into fresh particles (tools).
 *
 * Nothing in a file is trusted: counts, shapes, types and storage indices
 * are checked before they are used, and every problem is an error naming
 * the file and the dataset. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "mf_bodies.h"
#include "hdf5_internal.h"
#include "mf_error.h"
#include "mf_hdf5.h"

/* Far beyond any run (2^40 particles) but small enough that sizes computed
 * from it cannot overflow. */
#define MAX_PARTICLES ((int64_t)1 << 40)

static int open_snapshot(const char *path, hid_t *file)
{
    char detail[256];
    hid_t fapl = mf_h5_fapl();
    *file = fapl < 0 ? H5I_INVALID_HID : H5Fopen(path, H5F_ACC_RDONLY, fapl);
    /* Take the message before any other HDF5 call clears the error stack. */
    mf_h5_error_detail(detail, sizeof detail);
    mf_h5_close(&fapl);
    if (*file < 0)
        return MF_ERROR(MF_ERR_IO, "cannot open snapshot %s (%s)", path, detail);
    return 0;
}

static int read_header(hid_t file, const char *path, mf_hdf5_header *h)
{
    char what[MF_H5_PATH_MAX], detail[256];
    snprintf(what, sizeof what, "%s:/Header", path);
    htri_t exists = H5Lexists(file, "Header", H5P_DEFAULT);
    if (exists <= 0)
        return MF_ERROR(MF_ERR_INPUT, "snapshot %s has no /Header group", path);
    hid_t g = H5Gopen2(file, "Header", H5P_DEFAULT);
    if (g < 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot open the group (%s)", what,
                        mf_h5_error_detail(detail, sizeof detail));
    memset(h, 0, sizeof *h);
    int64_t step = 0;
    int rc = 0;
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "Time", H5T_NATIVE_DOUBLE, 0, &h->time, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "Step", H5T_NATIVE_INT64, 0, &step, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "TimeStep", H5T_NATIVE_DOUBLE, 0, &h->dt, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "Dimension", H5T_NATIVE_INT, 0, &h->dim, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "ParticleSpacing", H5T_NATIVE_DOUBLE, 0, &h->l0, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "NumPart_ThisFile", H5T_NATIVE_INT64, MF_NKINDS, h->npart, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "NumPart_Total", H5T_NATIVE_INT64, MF_NKINDS, h->npart_total, what), done);
    MF_CALL_GOTO(rc, mf_h5_attr_read(g, "NextId", H5T_NATIVE_INT64, 0, &h->next_id, what), done);
    h->step = (long)step;
    /* Optional (older snapshots lack it): the time-step controller's state. */
    if (H5Aexists(g, "NaturalTimeStep") > 0)
        MF_CALL_GOTO(rc, mf_h5_attr_read(g, "NaturalTimeStep", H5T_NATIVE_DOUBLE, 0, &h->dt_natural, what), done);

    /* CodeVersion is informational: read it if it is a readable string. */
    hid_t str = H5Tcopy(H5T_C_S1);
    if (str >= 0 && H5Tset_size(str, sizeof h->code_version) >= 0 &&
        mf_h5_attr_read(g, "CodeVersion", str, 0, h->code_version, what) != 0) {
        h->code_version[0] = '\0';
        mf_error_clear();
    }
    h->code_version[sizeof h->code_version - 1] = '\0';
    mf_h5_close(&str);

    if (h->dim != 2 && h->dim != 3) {
        rc = MF_ERROR(MF_ERR_INPUT, "%s: Dimension is %d, expected 2 or 3", what, h->dim);
        goto done;
    }
    if (!isfinite(h->time) || !isfinite(h->dt) || h->dt < 0 || step < 0 ||
        !isfinite(h->l0) || h->l0 < 0 || h->next_id < 0) {
        rc = MF_ERROR(MF_ERR_INPUT,
                      "%s: inconsistent header (Time %g, TimeStep %g, Step %lld, "
                      "ParticleSpacing %g, NextId %lld)",
                      what, h->time, h->dt, (long long)step, h->l0, (long long)h->next_id);
        goto done;
    }
    int64_t total = 0;
    for (int k = 0; k < MF_NKINDS; k++) {
        if (h->npart[k] < 0 || h->npart[k] > MAX_PARTICLES || h->npart[k] != h->npart_total[k]) {
            rc = MF_ERROR(MF_ERR_INPUT,
                          "%s: inconsistent particle counts for kind %d (NumPart_ThisFile %lld, "
                          "NumPart_Total %lld)",
                          what, k, (long long)h->npart[k], (long long)h->npart_total[k]);
            goto done;
        }
        total += h->npart[k];
    }
    if (total > MAX_PARTICLES)
        rc = MF_ERROR(MF_ERR_INPUT, "%s: %lld particles is not a sane count", what,
                      (long long)total);
done:
    H5Gclose(g);
    return rc;
}

int mf_hdf5_read_header(const char *path, mf_hdf5_header *h)
{
    mf_h5_quiet quiet;
    mf_h5_quiet_begin(&quiet);
    hid_t file;
    int rc = open_snapshot(path, &file);
    if (rc == 0) {
        rc = read_header(file, path, h);
        H5Fclose(file);
    }
    mf_h5_quiet_end(&quiet);
    if (rc != 0)
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    return 0;
}

/* ---- the particles -------------------------------------------------------- */

typedef struct snap_reader {
    const char *path;
    hid_t file;
    mf_particles *p;
    bool own_p;        /* particles created here: add every stored field */
    size_t total;
    uint8_t *filled;   /* total: slot already taken by a StorageIndex */
    int64_t *where;    /* storage index of each row of the current kind */
    void *buf;         /* one dataset of the current kind */
    size_t buf_size;
} snap_reader;

static int grow_buffer(snap_reader *r, size_t bytes, const char *what)
{
    if (bytes <= r->buf_size)
        return 0;
    if (mf_resize(&r->buf, bytes, 1))
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory (%zu bytes)", what, bytes);
    r->buf_size = bytes;
    return 0;
}

/* Open group/name, check it has `rows` rows of `ncomp` components of the
 * right class (integer or float), and read it whole into r->buf. */
static int read_dataset(snap_reader *r, hid_t group, const char *group_name, const char *name,
                        size_t rows, int ncomp, bool is_int, hid_t mem_type)
{
    char what[MF_H5_PATH_MAX], detail[256];
    snprintf(what, sizeof what, "%s:/%s/%s", r->path, group_name, name);
    if (H5Lexists(group, name, H5P_DEFAULT) <= 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: dataset is missing", what);
    hid_t dset = H5Dopen2(group, name, H5P_DEFAULT);
    if (dset < 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot open the dataset (%s)", what,
                        mf_h5_error_detail(detail, sizeof detail));
    mf_h5_shape s;
    int rc = mf_h5_dataset_shape(dset, &s, what);
    if (rc != 0)
        goto done;
    if (s.rows != rows || s.ncomp != ncomp || s.rank > 2 || s.precision == 0 ||
        s.is_int != is_int) {
        rc = MF_ERROR(MF_ERR_INPUT,
                      "%s: inconsistent dataset: %llu x %d %s values, expected %zu x %d %s "
                      "(the header's count for this kind)",
                      what, (unsigned long long)s.rows, s.ncomp,
                      s.precision == 0 ? "non-numeric" : s.is_int ? "integer" : "float", rows,
                      ncomp, is_int ? "integer" : "float");
        goto done;
    }
    MF_CALL_GOTO(rc, grow_buffer(r, rows * (size_t)ncomp * H5Tget_size(mem_type), what), done);
    if (rows > 0 && H5Dread(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, r->buf) < 0)
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot read the dataset (%s)", what,
                      mf_h5_error_detail(detail, sizeof detail));
done:
    H5Dclose(dset);
    return rc;
}

static void scatter(const snap_reader *r, size_t rows, void *dst, size_t row_bytes)
{
    const char *src = r->buf;
    for (size_t k = 0; k < rows; k++)
        memcpy((char *)dst + (size_t)r->where[k] * row_bytes, src + k * row_bytes, row_bytes);
}

/* A stored optional field: fill the matching field of the particles, add it
 * when the particles are ours, otherwise skip it. */
static int read_field(snap_reader *r, hid_t group, const char *group_name, const char *name,
                      size_t rows)
{
    char what[MF_H5_PATH_MAX], detail[256];
    snprintf(what, sizeof what, "%s:/%s/%s", r->path, group_name, name);
    mf_particles *p = r->p;
    int index = mf_particles_field_index(p, name);
    if (index < 0) {
        if (!r->own_p)
            return 0; /* stored but not requested by this run: not needed */
        hid_t dset = H5Dopen2(group, name, H5P_DEFAULT);
        if (dset < 0)
            return MF_ERROR(MF_ERR_IO, "%s: cannot open the dataset (%s)", what,
                            mf_h5_error_detail(detail, sizeof detail));
        mf_h5_shape s;
        int rc = mf_h5_dataset_shape(dset, &s, what);
        H5Dclose(dset);
        MF_CALL(rc);
        int type = s.is_int ? MF_FIELD_INT32 : MF_FIELD_DOUBLE;
        if (s.precision == 0 || s.ncomp < 1 || s.ncomp > 9 || s.rank > 2 ||
            strlen(name) >= sizeof p->field[0].name)
            return 0; /* not a field particles can hold */
        MF_CALL(mf_particles_request_field(p, name, s.ncomp, type, true, &index));
        size_t elem = type == MF_FIELD_DOUBLE ? sizeof(double) : sizeof(int32_t);
        memset(p->field[index].data, 0, r->total * (size_t)s.ncomp * elem);
    }
    mf_field *field = &p->field[index];
    bool is_int = field->type == MF_FIELD_INT32;
    hid_t mem_type = is_int ? H5T_NATIVE_INT32 : H5T_NATIVE_DOUBLE;
    MF_CALL(read_dataset(r, group, group_name, name, rows, field->ncomp, is_int, mem_type));
    scatter(r, rows, field->data, (size_t)field->ncomp * H5Tget_size(mem_type));
    return 0;
}

static int read_kind_data(snap_reader *r, hid_t g, const char *group_name, int kind, size_t rows)
{
    char what[MF_H5_PATH_MAX];
    mf_particles *p = r->p;

    /* Where each row goes, first: everything else is scattered with it. */
    MF_CALL(read_dataset(r, g, group_name, "StorageIndex", rows, 1, true, H5T_NATIVE_INT64));
    memcpy(r->where, r->buf, rows * sizeof *r->where);
    snprintf(what, sizeof what, "%s:/%s/StorageIndex", r->path, group_name);
    for (size_t k = 0; k < rows; k++) {
        int64_t at = r->where[k];
        if (at < 0 || (uint64_t)at >= r->total)
            return MF_ERROR(MF_ERR_INPUT, "%s: index %lld out of range [0, %zu)", what,
                            (long long)at, r->total);
        if (r->filled[at])
            return MF_ERROR(MF_ERR_INPUT, "%s: index %lld used twice", what, (long long)at);
        r->filled[at] = 1;
        p->kind[at] = (uint8_t)kind;
    }

    MF_CALL(read_dataset(r, g, group_name, "Coordinates", rows, 3, false, H5T_NATIVE_DOUBLE));
    const double *x = r->buf;
    for (size_t k = 0; k < 3 * rows; k++)
        if (!isfinite(x[k]))
            return MF_ERROR(MF_ERR_INPUT,
                            "%s:/%s/Coordinates: row %zu (storage index %lld) is not finite "
                            "(%g)",
                            r->path, group_name, k / 3, (long long)r->where[k / 3], x[k]);
    scatter(r, rows, p->pos, 3 * sizeof(double));

    MF_CALL(read_dataset(r, g, group_name, "Velocities", rows, 3, false, H5T_NATIVE_DOUBLE));
    scatter(r, rows, p->vel, 3 * sizeof(double));

    MF_CALL(read_dataset(r, g, group_name, "ParticleIDs", rows, 1, true, H5T_NATIVE_INT64));
    const int64_t *ids = r->buf;
    for (size_t k = 0; k < rows; k++)
        if (ids[k] < 0 || ids[k] >= p->next_id)
            return MF_ERROR(MF_ERR_INPUT,
                            "%s:/%s/ParticleIDs: id %lld of row %zu is not below the header's "
                            "NextId %lld",
                            r->path, group_name, (long long)ids[k], k, (long long)p->next_id);
    scatter(r, rows, p->id, sizeof(int64_t));

    char (*names)[MF_H5_NAME_MAX];
    size_t nnames;
    snprintf(what, sizeof what, "%s:/%s", r->path, group_name);
    MF_CALL(mf_h5_list_datasets(g, &names, &nnames, what));
    int rc = 0;
    for (size_t k = 0; k < nnames && rc == 0; k++)
        if (!mf_h5_is_core_dataset(names[k]))
            rc = read_field(r, g, group_name, names[k], rows);
    free(names);
    MF_CALL(rc);
    return 0;
}

static int read_kind(snap_reader *r, int kind, size_t rows)
{
    char group_name[32], detail[256];
    mf_h5_part_group(kind, group_name, sizeof group_name);
    htri_t exists = H5Lexists(r->file, group_name, H5P_DEFAULT);
    if (rows == 0) {
        /* The header says none: a group here would be data we would drop. */
        if (exists > 0)
            return MF_ERROR(MF_ERR_INPUT, "%s: /%s is present but the header counts no %s "
                            "particles", r->path, group_name, mf_h5_kind_name(kind));
        return 0;
    }
    if (exists <= 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: /%s is missing (the header counts %zu %s particles)",
                        r->path, group_name, rows, mf_h5_kind_name(kind));
    hid_t g = H5Gopen2(r->file, group_name, H5P_DEFAULT);
    if (g < 0)
        return MF_ERROR(MF_ERR_IO, "%s:/%s: cannot open the group (%s)", r->path, group_name,
                        mf_h5_error_detail(detail, sizeof detail));
    int rc = read_kind_data(r, g, group_name, kind, rows);
    H5Gclose(g);
    MF_CALL(rc);
    return 0;
}

/* Make room for the particles and zero the fields: those the file does not
 * hold start from zero, like the fields of a new particle. */
static int prepare_particles(snap_reader *r, mf_sim *sim, const mf_hdf5_header *h)
{
    if (sim->dim != 0 && sim->dim != h->dim)
        return MF_ERROR(MF_ERR_INPUT, "snapshot %s is %d-D but the case is %d-D", r->path,
                        h->dim, sim->dim);
    size_t cap = r->total > 0 ? r->total : 1;
    if (!sim->p) {
        MF_CALL(mf_particles_create(h->dim, cap, &sim->p));
        r->own_p = true;
    }
    r->p = sim->p;
    if (r->p->dim != h->dim)
        return MF_ERROR(MF_ERR_INPUT, "snapshot %s is %d-D but the particles are %d-D", r->path,
                        h->dim, r->p->dim);
    if (r->p->cap < r->total)
        MF_CALL(mf_particles_reserve(r->p, r->total));
    for (int f = 0; f < r->p->nfields; f++) {
        mf_field *field = &r->p->field[f];
        size_t elem = field->type == MF_FIELD_INT32 ? sizeof(int32_t) : sizeof(double);
        memset(field->data, 0, r->total * (size_t)field->ncomp * elem);
    }
    /* Ids are checked against NextId while reading. */
    r->p->next_id = h->next_id;
    return 0;
}

static int read_particles(snap_reader *r, mf_sim *sim, const mf_hdf5_header *h)
{
    MF_CALL(prepare_particles(r, sim, h));
    size_t n = r->total > 0 ? r->total : 1;
    r->filled = calloc(n, 1);
    r->where = malloc(n * sizeof *r->where);
    if (!r->filled || !r->where)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory for %zu particles", r->path, n);
    for (int kind = 0; kind < MF_NKINDS; kind++)
        MF_CALL(read_kind(r, kind, (size_t)h->npart[kind]));
    /* Counts sum to total and no index repeats, so every slot is taken. */
    r->p->n = r->total;
    r->p->n_owned = r->total;
    return 0;
}

/* /RigidBodies/<name> (hdf5_writer.c's write_bodies) into the case's bodies:
 * a restart goes on with each body's state, impulses included. Only when
 * the reading sim has bodies (a metric reads snapshots without a scene). */
static int read_bodies(hid_t file, const char *path, mf_sim *sim)
{
    mf_walls *ws = sim->walls;
    if (mf_bodies_count(ws) == 0)
        return 0;
    char what[MF_H5_PATH_MAX + 128], link[128];
    for (size_t k = 0; k < ws->n; k++) {
        mf_wall *w = &ws->w[k];
        if (!w->body)
            continue;
        snprintf(link, sizeof link, "RigidBodies/%s", w->name);
        snprintf(what, sizeof what, "%s:/%s", path, link);
        if (H5Lexists(file, "RigidBodies", H5P_DEFAULT) <= 0 ||
            H5Lexists(file, link, H5P_DEFAULT) <= 0)
            return MF_ERROR(MF_ERR_INPUT, "cannot restart: snapshot %s has no state of rigid "
                            "body '%s' (/%s)", path, w->name, link);
        hid_t g = H5Gopen2(file, link, H5P_DEFAULT);
        if (g < 0)
            return MF_ERROR(MF_ERR_IO, "%s: cannot open the group", what);
        mf_body_momentum b;
        memset(&b, 0, sizeof b);
        const struct {
            const char *name;
            double *v;
            size_t n;
        } a[] = {{"Mass", &b.mass, 0},           {"Centre", b.centre, 3},
                 {"Rotation", b.rotation, 9},    {"Velocity", b.velocity, 3},
                 {"AngularVelocity", b.omega, 3}, {"AngularMomentum", b.angular, 3},
                 {"Impulse", b.impulse, 3},      {"AngularImpulse", b.angular_impulse, 3}};
        int rc = 0;
        for (size_t i = 0; rc == 0 && i < sizeof a / sizeof a[0]; i++)
            rc = mf_h5_attr_read(g, a[i].name, H5T_NATIVE_DOUBLE, a[i].n, a[i].v, what);
        H5Gclose(g);
        MF_CALL(rc);
        MF_CALL(mf_body_set(w, &b, what));
    }
    return 0;
}

int mf_hdf5_read_snapshot(const char *path, mf_sim *sim)
{
    mf_h5_quiet quiet;
    mf_h5_quiet_begin(&quiet);
    snap_reader r = {.path = path, .file = H5I_INVALID_HID};
    mf_hdf5_header h;
    int rc = open_snapshot(path, &r.file);
    if (rc == 0)
        rc = read_header(r.file, path, &h);
    if (rc == 0) {
        for (int k = 0; k < MF_NKINDS; k++)
            r.total += (size_t)h.npart[k];
        rc = read_particles(&r, sim, &h);
    }
    if (rc == 0)
        rc = read_bodies(r.file, path, sim);
    mf_h5_close(&r.file);
    mf_h5_quiet_end(&quiet);
    free(r.filled);
    free(r.where);
    free(r.buf);
    if (rc != 0) {
        if (r.own_p) {
            mf_particles_destroy(sim->p);
            sim->p = NULL;
        }
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    sim->time = h.time;
    sim->step = h.step;
    sim->dt = h.dt;
    sim->dt_natural = h.dt_natural;
    if (sim->dim == 0)
        sim->dim = h.dim;
    if (sim->l0 == 0)
        sim->l0 = h.l0;
    return 0;
}
