/* xdmf_index.c: <output>/particles.xdmf, the file ParaView opens to see all
 * snapshots as one time series.
 *
 * XDMF 2.0 syntax, which all three of ParaView 5.11's XDMF readers read
 * (Xdmf3ReaderS, the default for .xdmf; Xdmf3ReaderT; the legacy
 * XDMFReader): a Temporal collection of Spatial collections, one per
 * snapshot, each holding one Polyvertex grid per particle kind present
 * (named "fluid", "wall", ...). Geometry is XYZ (z = 0 in 2-D). The
 * topology's connectivity is the kind's PointIndex dataset: the Xdmf3
 * readers make no cells without it, and points without cells render as an
 * empty frame. Every other dataset of the kind is a node attribute, named
 * with its unit ("Pressure [Pa]"); Kind tells the kinds apart where the
 * default reader merges the grids into one. Times are written without
 * rounding noise (mf_timetext.h). Paths are relative to the index, so the
 * output folder can be moved or copied as a whole.
 *
 * The index is described from the files themselves (what they hold, not
 * what we meant to write), kept in memory by the writer and rewritten after
 * each snapshot through a .tmp and a rename. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_alloc.h"
#include "hdf5_internal.h"
#include "mf_error.h"
#include "mf_fs.h"
#include "mf_hdf5.h"
#include "mf_timetext.h"

static void snap_free(mf_xdmf_snap *s)
{
    for (int k = 0; k < MF_NKINDS; k++) {
        free(s->sets[k]);
        s->sets[k] = NULL;
        s->nsets[k] = 0;
    }
}

static int describe_kind(hid_t g, const char *what, mf_xdmf_snap *s, int kind)
{
    char (*names)[MF_H5_NAME_MAX];
    size_t nnames;
    MF_CALL(mf_h5_list_datasets(g, &names, &nnames, what));
    mf_xdmf_set *sets = calloc(nnames > 0 ? nnames : 1, sizeof *sets);
    if (!sets) {
        free(names);
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory", what);
    }
    size_t nsets = 0;
    int64_t rows = -1;
    int rc = 0;
    for (size_t k = 0; k < nnames && rc == 0; k++) {
        /* Where a particle sits in memory means nothing in ParaView. */
        if (strcmp(names[k], "StorageIndex") == 0)
            continue;
        hid_t dset = H5Dopen2(g, names[k], H5P_DEFAULT);
        if (dset < 0)
            continue;
        mf_h5_shape shape;
        char unit[32];
        rc = mf_h5_dataset_shape(dset, &shape, what);
        if (mf_h5_attr_read_string(dset, "Units", unit, sizeof unit) != 0)
            unit[0] = '\0';
        H5Dclose(dset);
        if (rc != 0 || shape.precision == 0 || shape.rank < 1 || shape.rank > 2)
            continue;
        if (strcmp(names[k], "Coordinates") == 0)
            rows = (int64_t)shape.rows;
        if (strcmp(names[k], "PointIndex") == 0) {
            /* The vertex cells: used as the topology, not shown as a field. */
            s->point_index[kind] = shape.rank == 1 && shape.is_int && shape.precision == 4;
            continue;
        }
        mf_xdmf_set *set = &sets[nsets++];
        memcpy(set->name, names[k], sizeof set->name);
        memcpy(set->unit, unit, sizeof set->unit);
        set->ncomp = shape.ncomp;
        set->is_int = shape.is_int;
        set->is_unsigned = shape.is_unsigned;
        set->precision = shape.precision;
    }
    free(names);
    if (rc != 0 || rows <= 0) {
        /* No geometry (or an empty kind): nothing ParaView can show. */
        free(sets);
        return rc;
    }
    s->n[kind] = rows;
    s->nsets[kind] = nsets;
    s->sets[kind] = sets;
    return 0;
}

static int describe_file(hid_t file, const char *path, mf_xdmf_snap *s)
{
    char what[MF_H5_PATH_MAX + 64], detail[256], group_name[32];
    snprintf(what, sizeof what, "%s:/Header", path);
    hid_t g = H5Gopen2(file, "Header", H5P_DEFAULT);
    if (g < 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: cannot open the group (%s)", what,
                        mf_h5_error_detail(detail, sizeof detail));
    int rc = mf_h5_attr_read(g, "Time", H5T_NATIVE_DOUBLE, 0, &s->time, what);
    H5Gclose(g);
    MF_CALL(rc);
    for (int kind = 0; kind < MF_NKINDS; kind++) {
        mf_h5_part_group(kind, group_name, sizeof group_name);
        if (H5Lexists(file, group_name, H5P_DEFAULT) <= 0)
            continue;
        snprintf(what, sizeof what, "%s:/%s", path, group_name);
        g = H5Gopen2(file, group_name, H5P_DEFAULT);
        if (g < 0)
            return MF_ERROR(MF_ERR_IO, "%s: cannot open the group (%s)", what,
                            mf_h5_error_detail(detail, sizeof detail));
        rc = describe_kind(g, what, s, kind);
        H5Gclose(g);
        MF_CALL(rc);
    }
    return 0;
}

int mf_xdmf_describe(const char *output_dir, int index, mf_xdmf_snap *s)
{
    char path[MF_H5_PATH_MAX], detail[256];
    memset(s, 0, sizeof *s);
    s->index = index;
    MF_CALL(mf_h5_snapshot_path(output_dir, index, path, sizeof path));
    mf_h5_quiet quiet;
    mf_h5_quiet_begin(&quiet);
    int rc = 0;
    hid_t fapl = mf_h5_fapl();
    hid_t file = fapl < 0 ? H5I_INVALID_HID : H5Fopen(path, H5F_ACC_RDONLY, fapl);
    mf_h5_error_detail(detail, sizeof detail); /* before another call clears it */
    mf_h5_close(&fapl);
    if (file < 0)
        rc = MF_ERROR(MF_ERR_IO, "cannot open snapshot %s (%s)", path, detail);
    else
        rc = describe_file(file, path, s);
    mf_h5_close(&file);
    mf_h5_quiet_end(&quiet);
    if (rc != 0) {
        snap_free(s);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    return 0;
}

int mf_xdmf_index_add(mf_xdmf_index *x, mf_xdmf_snap *s)
{
    size_t at = 0;
    while (at < x->n && x->snap[at].index < s->index)
        at++;
    if (at < x->n && x->snap[at].index == s->index) {
        snap_free(&x->snap[at]);
        x->snap[at] = *s;
        return 0;
    }
    if (x->n == x->cap) {
        size_t cap = x->cap ? 2 * x->cap : 16;
        if (mf_resize(&x->snap, cap, sizeof *x->snap)) {
            snap_free(s);
            return MF_ERROR(MF_ERR_MEMORY, "out of memory for the XDMF index");
        }
        x->cap = cap;
    }
    memmove(&x->snap[at + 1], &x->snap[at], (x->n - at) * sizeof *x->snap);
    x->snap[at] = *s;
    x->n++;
    return 0;
}

void mf_xdmf_index_remove(mf_xdmf_index *x, int index)
{
    for (size_t k = 0; k < x->n; k++)
        if (x->snap[k].index == index) {
            snap_free(&x->snap[k]);
            memmove(&x->snap[k], &x->snap[k + 1], (x->n - k - 1) * sizeof *x->snap);
            x->n--;
            return;
        }
}

int mf_xdmf_index_scan(mf_xdmf_index *x, const char *output_dir)
{
    int *indices;
    size_t n;
    MF_CALL(mf_h5_scan_snapshots(output_dir, &indices, &n));
    int rc = 0;
    for (size_t k = 0; k < n && rc == 0; k++) {
        mf_xdmf_snap s;
        if (mf_xdmf_describe(output_dir, indices[k], &s) != 0) {
            mf_error_clear(); /* unreadable: the reader skips it too */
            continue;
        }
        rc = mf_xdmf_index_add(x, &s);
    }
    free(indices);
    MF_CALL(rc);
    return 0;
}

void mf_xdmf_index_free(mf_xdmf_index *x)
{
    for (size_t k = 0; k < x->n; k++)
        snap_free(&x->snap[k]);
    free(x->snap);
    x->snap = NULL;
    x->n = x->cap = 0;
}

static const char *attribute_type(int ncomp)
{
    switch (ncomp) {
    case 1: return "Scalar";
    case 3: return "Vector";
    case 6: return "Tensor6";
    case 9: return "Tensor";
    default: return "Matrix";
    }
}

/* Names are identifiers, but the XML must stay well-formed whatever a
 * plug-in calls its field. */
static void put_xml(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

static const char *number_type(const mf_xdmf_set *set)
{
    if (!set->is_int)
        return "Float";
    if (set->precision == 1)
        return set->is_unsigned ? "UChar" : "Char";
    return set->is_unsigned ? "UInt" : "Int";
}

static void put_data_item(FILE *f, const mf_xdmf_snap *s, int kind, const mf_xdmf_set *set)
{
    fprintf(f, "          <DataItem Dimensions=\"%lld", (long long)s->n[kind]);
    if (set->ncomp > 1)
        fprintf(f, " %d", set->ncomp);
    fprintf(f, "\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">snapshot_%06d.h5:/PartType%d/",
            number_type(set), set->precision, s->index, kind);
    put_xml(f, set->name);
    fputs("</DataItem>\n", f);
}

/* The name ParaView shows: the dataset's, with its unit where it has one
 * ("Pressure [Pa]", "Velocities [m/s]"; "NumberDensity", "Flags"). */
static void put_attribute_name(FILE *f, const mf_xdmf_set *set)
{
    put_xml(f, set->name);
    if (set->unit[0] && strcmp(set->unit, "1") != 0) {
        fputs(" [", f);
        put_xml(f, set->unit);
        fputc(']', f);
    }
}

static void put_snapshot(FILE *f, const mf_xdmf_snap *s)
{
    fprintf(f, "    <Grid Name=\"snapshot_%06d\" GridType=\"Collection\" CollectionType=\"Spatial\">\n",
            s->index);
    char time[32];
    fprintf(f, "      <Time Value=\"%s\"/>\n", mf_time_text(s->time, time, sizeof time));
    for (int kind = 0; kind < MF_NKINDS; kind++) {
        if (s->n[kind] <= 0)
            continue;
        fprintf(f, "      <Grid Name=\"%s\" GridType=\"Uniform\">\n", mf_h5_kind_name(kind));
        if (s->point_index[kind]) {
            const long long n = (long long)s->n[kind];
            fprintf(f, "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%lld\" "
                       "NodesPerElement=\"1\">\n"
                       "          <DataItem Dimensions=\"%lld\" NumberType=\"Int\" Precision=\"4\" "
                       "Format=\"HDF\">snapshot_%06d.h5:/PartType%d/PointIndex</DataItem>\n"
                       "        </Topology>\n",
                    n, n, s->index, kind);
        } else { /* written before PointIndex: the legacy reader still shows it */
            fprintf(f, "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%lld\"/>\n",
                    (long long)s->n[kind]);
        }
        for (size_t k = 0; k < s->nsets[kind]; k++) {
            const mf_xdmf_set *set = &s->sets[kind][k];
            if (strcmp(set->name, "Coordinates") != 0)
                continue;
            fputs("        <Geometry GeometryType=\"XYZ\">\n", f);
            put_data_item(f, s, kind, set);
            fputs("        </Geometry>\n", f);
        }
        for (size_t k = 0; k < s->nsets[kind]; k++) {
            const mf_xdmf_set *set = &s->sets[kind][k];
            if (strcmp(set->name, "Coordinates") == 0)
                continue;
            fputs("        <Attribute Name=\"", f);
            put_attribute_name(f, set);
            fprintf(f, "\" AttributeType=\"%s\" Center=\"Node\">\n", attribute_type(set->ncomp));
            put_data_item(f, s, kind, set);
            fputs("        </Attribute>\n", f);
        }
        fputs("      </Grid>\n", f);
    }
    fputs("    </Grid>\n", f);
}

/* The snapshots of the current run: walking back from the newest, keep each
 * one whose time is before the last kept. Leftovers of an older run that
 * went further in time are left out (ParaView needs times that increase). */
static int select_lineage(const mf_xdmf_index *x, bool **keep)
{
    *keep = calloc(x->n > 0 ? x->n : 1, sizeof **keep);
    if (!*keep)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for the XDMF index");
    bool any = false;
    double next_time = 0;
    for (size_t k = x->n; k-- > 0;) {
        const mf_xdmf_snap *s = &x->snap[k];
        bool has_particles = false;
        for (int kind = 0; kind < MF_NKINDS; kind++)
            has_particles = has_particles || s->n[kind] > 0;
        if (!any || s->time < next_time) {
            (*keep)[k] = has_particles;
            next_time = s->time;
            any = true;
        }
    }
    return 0;
}

int mf_xdmf_index_write(const mf_xdmf_index *x, const char *output_dir)
{
    char path[MF_H5_PATH_MAX];
    int w1 = snprintf(path, sizeof path, "%s/particles.xdmf", output_dir);
    if (w1 < 0 || (size_t)w1 >= sizeof path)
        return MF_ERROR(MF_ERR_INPUT, "output path too long: %s", output_dir);
    bool *keep;
    MF_CALL(select_lineage(x, &keep));
    mf_replace out;
    int rc = mf_replace_open(&out, path, "w");
    if (rc != 0) {
        free(keep);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    FILE *f = out.f;
    fputs("<?xml version=\"1.0\" ?>\n"
          "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
          "<Xdmf Version=\"2.0\">\n"
          "  <Domain>\n"
          "  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
          f);
    for (size_t k = 0; k < x->n; k++)
        if (keep[k])
            put_snapshot(f, &x->snap[k]);
    fputs("  </Grid>\n"
          "  </Domain>\n"
          "</Xdmf>\n",
          f);
    free(keep);
    MF_CALL(mf_replace_commit(&out, 0));
    return 0;
}

int mf_hdf5_write_xdmf_index(const char *output_dir)
{
    mf_xdmf_index x = {0};
    int rc = mf_xdmf_index_scan(&x, output_dir);
    if (rc == 0)
        rc = mf_xdmf_index_write(&x, output_dir);
    mf_xdmf_index_free(&x);
    MF_CALL(rc);
    return 0;
}
