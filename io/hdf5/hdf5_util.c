/* hdf5_util.c: the small HDF5 helpers the snapshot code shares: silencing
 * HDF5's stderr output, turning its error stack into our messages, closing
 * handles, attributes, listing and measuring datasets. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hdf5_internal.h"
#include "mf_error.h"

void mf_h5_quiet_begin(mf_h5_quiet *q)
{
    q->func = NULL;
    q->data = NULL;
    H5Eget_auto2(H5E_DEFAULT, &q->func, &q->data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

void mf_h5_quiet_end(const mf_h5_quiet *q)
{
    H5Eset_auto2(H5E_DEFAULT, q->func, q->data);
}

typedef struct detail_ctx {
    char *buf;
    size_t len;
} detail_ctx;

/* Walking upward, the first record is where the failure was detected: the
 * most specific message ("truncated file: eof = ..."). */
static herr_t detail_walk(unsigned n, const H5E_error2_t *err, void *data)
{
    detail_ctx *ctx = data;
    if (n == 0 && err->desc)
        snprintf(ctx->buf, ctx->len, "%s", err->desc);
    return 0;
}

const char *mf_h5_error_detail(char *buf, size_t len)
{
    if (len == 0)
        return buf;
    buf[0] = '\0';
    detail_ctx ctx = {buf, len};
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, detail_walk, &ctx);
    if (buf[0] == '\0')
        snprintf(buf, len, "no details from HDF5");
    return buf;
}

void mf_h5_close(hid_t *id)
{
    if (*id < 0)
        return;
    switch (H5Iget_type(*id)) {
    case H5I_FILE: H5Fclose(*id); break;
    case H5I_GROUP: H5Gclose(*id); break;
    case H5I_DATASET: H5Dclose(*id); break;
    case H5I_DATASPACE: H5Sclose(*id); break;
    case H5I_DATATYPE: H5Tclose(*id); break;
    case H5I_GENPROP_LST: H5Pclose(*id); break;
    case H5I_ATTR: H5Aclose(*id); break;
    default: break;
    }
    *id = H5I_INVALID_HID;
}

void mf_h5_part_group(int kind, char *buf, size_t len)
{
    snprintf(buf, len, "PartType%d", kind);
}

const char *mf_h5_kind_name(int kind)
{
    static const char *const names[MF_NKINDS] = {"fluid", "wall", "dummy", "inlet", "outlet"};
    return kind >= 0 && kind < MF_NKINDS ? names[kind] : "unknown";
}

hid_t mf_h5_fapl(void)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
#if H5_VERSION_GE(1, 10, 7)
    if (fapl >= 0)
        H5Pset_file_locking(fapl, true, true);
#endif
    return fapl;
}

const char *mf_h5_format_double(double x, char *buf, size_t len)
{
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, len, "%.*g", digits, x);
        if (strtod(buf, NULL) == x)
            break;
    }
    return buf; /* NaN and infinities: the %.17g text */
}

/* Known units; any other dataset is dimensionless or counted ("1"). */
static const struct { const char *name, *unit; } unit_table[] = {
    {"Coordinates", "m"},
    {"Velocities", "m/s"},
    {"Pressure", "Pa"},
    {"Density", "kg/m^3"},
    {"Acceleration", "m/s^2"},
    {"Temperature", "K"},
    {"Vorticity", "1/s"},
    {"LightPressure", "Pa"},          /* multiFluid: the gas pass of the two-step pressure */
    {"Curvature", "1/m"},             /* surfaceTension */
    {"SurfaceTension", "m/s^2"},      /* surfaceTension: its acceleration */
    {"ConvectionVelocity", "m/s"},    /* MPS-MAFL */
    {"PointVelocity", "m/s"},         /* MPS-MAFL */
};

const char *mf_h5_unit(const char *dataset)
{
    for (size_t k = 0; k < sizeof unit_table / sizeof unit_table[0]; k++)
        if (strcmp(unit_table[k].name, dataset) == 0)
            return unit_table[k].unit;
    return "1";
}

bool mf_h5_is_core_dataset(const char *name)
{
    return strcmp(name, "Coordinates") == 0 || strcmp(name, "Velocities") == 0 ||
           strcmp(name, "ParticleIDs") == 0 || strcmp(name, "StorageIndex") == 0 ||
           strcmp(name, "PointIndex") == 0 || strcmp(name, "Kind") == 0;
}

int mf_h5_attr_write(hid_t obj, const char *name, hid_t file_type, hid_t mem_type, size_t n,
                     const void *buf, const char *what)
{
    char detail[256];
    hsize_t dims[1] = {n};
    hid_t space = n == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, dims, NULL);
    hid_t attr = H5I_INVALID_HID;
    int rc = 0;
    if (space < 0 ||
        (attr = H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(attr, mem_type, buf) < 0)
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot write attribute %s (%s)", what, name,
                      mf_h5_error_detail(detail, sizeof detail));
    mf_h5_close(&attr);
    mf_h5_close(&space);
    return rc;
}

int mf_h5_attr_write_string(hid_t obj, const char *name, const char *value, const char *what)
{
    char detail[256];
    /* Fixed-length, NUL-terminated: what h5dump, h5py and SWIFT tools expect. */
    hid_t type = H5Tcopy(H5T_C_S1);
    int rc = 0;
    if (type < 0 || H5Tset_size(type, strlen(value) + 1) < 0 ||
        H5Tset_strpad(type, H5T_STR_NULLTERM) < 0) {
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot make a string type for attribute %s (%s)", what,
                      name, mf_h5_error_detail(detail, sizeof detail));
    } else {
        rc = mf_h5_attr_write(obj, name, type, type, 0, value, what);
    }
    mf_h5_close(&type);
    return rc;
}

int mf_h5_attr_read(hid_t obj, const char *name, hid_t mem_type, size_t n, void *buf,
                    const char *what)
{
    char detail[256];
    htri_t exists = H5Aexists(obj, name);
    if (exists < 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot look up attribute %s (%s)", what, name,
                        mf_h5_error_detail(detail, sizeof detail));
    if (exists == 0)
        return MF_ERROR(MF_ERR_INPUT, "%s: attribute %s is missing", what, name);
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    hid_t space = attr < 0 ? H5I_INVALID_HID : H5Aget_space(attr);
    int rc = 0;
    hssize_t npoints = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
    size_t want = n == 0 ? 1 : n;
    if (npoints < 0) {
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot open attribute %s (%s)", what, name,
                      mf_h5_error_detail(detail, sizeof detail));
    } else if ((size_t)npoints != want) {
        rc = MF_ERROR(MF_ERR_INPUT, "%s: attribute %s has %lld values, expected %zu", what, name,
                      (long long)npoints, want);
    } else if (H5Aread(attr, mem_type, buf) < 0) {
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot read attribute %s (%s)", what, name,
                      mf_h5_error_detail(detail, sizeof detail));
    }
    mf_h5_close(&space);
    mf_h5_close(&attr);
    return rc;
}

int mf_h5_attr_read_string(hid_t obj, const char *name, char *buf, size_t len)
{
    buf[0] = '\0';
    if (H5Aexists(obj, name) <= 0)
        return 0;
    hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    hid_t type = attr < 0 ? H5I_INVALID_HID : H5Aget_type(attr);
    int rc = 0;
    if (type < 0 || H5Tget_class(type) != H5T_STRING || H5Tis_variable_str(type) != 0 ||
        H5Tget_size(type) >= len) {
        rc = -1; /* not a short fixed-length string: not ours */
    } else {
        hid_t mem = H5Tcopy(type);
        if (mem < 0 || H5Tset_size(mem, len) < 0 || H5Tset_strpad(mem, H5T_STR_NULLTERM) < 0 ||
            H5Aread(attr, mem, buf) < 0)
            rc = -1;
        mf_h5_close(&mem);
        buf[len - 1] = '\0';
    }
    mf_h5_close(&type);
    mf_h5_close(&attr);
    if (rc != 0)
        buf[0] = '\0';
    return rc;
}

int mf_h5_list_datasets(hid_t group, char (**names)[MF_H5_NAME_MAX], size_t *n, const char *what)
{
    char detail[256];
    H5G_info_t info;
    *names = NULL;
    *n = 0;
    if (H5Gget_info(group, &info) < 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot list the group (%s)", what,
                        mf_h5_error_detail(detail, sizeof detail));
    if (info.nlinks == 0)
        return 0;
    char (*list)[MF_H5_NAME_MAX] = malloc(info.nlinks * sizeof *list);
    if (!list)
        return MF_ERROR(MF_ERR_MEMORY, "%s: out of memory listing %llu datasets", what,
                        (unsigned long long)info.nlinks);
    size_t count = 0;
    for (hsize_t i = 0; i < info.nlinks; i++) {
        ssize_t len = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i,
                                         list[count], MF_H5_NAME_MAX, H5P_DEFAULT);
        if (len < 0) {
            free(list);
            return MF_ERROR(MF_ERR_IO, "%s: cannot list the group (%s)", what,
                            mf_h5_error_detail(detail, sizeof detail));
        }
        if (len >= MF_H5_NAME_MAX)
            continue; /* longer than any field name: not ours */
        hid_t obj = H5Oopen(group, list[count], H5P_DEFAULT);
        if (obj < 0) /* a dangling link: nothing to read */
            continue;
        bool is_dataset = H5Iget_type(obj) == H5I_DATASET;
        H5Oclose(obj);
        if (is_dataset)
            count++;
    }
    *names = list;
    *n = count;
    return 0;
}

int mf_h5_dataset_shape(hid_t dset, mf_h5_shape *s, const char *what)
{
    char detail[256];
    hid_t space = H5Dget_space(dset);
    hsize_t dims[H5S_MAX_RANK];
    int rank = space < 0 ? -1 : H5Sget_simple_extent_dims(space, dims, NULL);
    if (rank < 0 || rank > H5S_MAX_RANK) {
        int rc = MF_ERROR(MF_ERR_IO, "%s: cannot read the dataset's shape (%s)", what,
                          mf_h5_error_detail(detail, sizeof detail));
        mf_h5_close(&space);
        return rc;
    }
    hid_t type = H5Dget_type(dset);
    int rc = 0;
    H5T_class_t cls = type < 0 ? H5T_NO_CLASS : H5Tget_class(type);
    size_t size = type < 0 ? 0 : H5Tget_size(type);
    if (cls == H5T_NO_CLASS || size == 0) {
        rc = MF_ERROR(MF_ERR_IO, "%s: cannot read the dataset's type (%s)", what,
                      mf_h5_error_detail(detail, sizeof detail));
    } else {
        memset(s, 0, sizeof *s);
        s->rank = rank;
        s->rows = rank == 0 ? 1 : dims[0];
        hsize_t ncomp = 1;
        for (int k = 1; k < rank; k++)
            ncomp *= dims[k];
        s->ncomp = ncomp > 1000000 ? -1 : (int)ncomp;
        s->is_int = cls == H5T_INTEGER;
        s->is_unsigned = cls == H5T_INTEGER && H5Tget_sign(type) == H5T_SGN_NONE;
        s->precision = cls == H5T_INTEGER || cls == H5T_FLOAT ? (int)size : 0;
    }
    mf_h5_close(&type);
    mf_h5_close(&space);
    return rc;
}
