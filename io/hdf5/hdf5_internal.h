/* hdf5_internal.h: helpers shared by the HDF5 snapshot files of io/
 * (hdf5_util.c, hdf5_files.c, hdf5_writer.c, hdf5_params.c, hdf5_reader.c,
 * xdmf_index.c, hdf5_module.c). Not installed, not for other modules: they
 * use mf_hdf5.h. */
#ifndef MF_HDF5_INTERNAL_H
#define MF_HDF5_INTERNAL_H

#include <hdf5.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mf_dict.h"
#include "mf_particles.h"

#define MF_H5_PATH_MAX 4096
#define MF_H5_NAME_MAX 64 /* dataset names we handle; longer ones are skipped */

/* ---- hdf5_util.c: error handling, handles, attributes, names ----------- */

/* HDF5 prints its error stack to stderr by default; we turn that off while
 * our functions run and restore whatever the caller had afterwards. */
typedef struct mf_h5_quiet {
    H5E_auto2_t func;
    void *data;
} mf_h5_quiet;
void mf_h5_quiet_begin(mf_h5_quiet *q);
void mf_h5_quiet_end(const mf_h5_quiet *q);

/* The innermost message of HDF5's current error stack ("truncated file..."),
 * or "" when there is none. Call right after the failing HDF5 call. */
const char *mf_h5_error_detail(char *buf, size_t len);

/* Close any HDF5 handle (file, group, dataset, dataspace, type, property
 * list, attribute) if valid, and invalidate it. Safe on H5I_INVALID_HID. */
void mf_h5_close(hid_t *id);

/* "PartType<k>" */
void mf_h5_part_group(int kind, char *buf, size_t len);
/* "fluid", "wall", "dummy", "inlet", "outlet": KindName and XDMF grid names. */
const char *mf_h5_kind_name(int kind);
/* File access properties for our files: file locking is kept, but ignored
 * where the file system has it disabled (NFS, Lustre without flock). */
hid_t mf_h5_fapl(void);
/* The shortest of %.15g, %.16g, %.17g that reads back to exactly x ("0.1",
 * not "0.10000000000000001"): readable and lossless. buf >= 32 bytes. */
const char *mf_h5_format_double(double x, char *buf, size_t len);
/* Read a string attribute into buf ("" and 0 when absent; <0 on a read
 * error). */
int mf_h5_attr_read_string(hid_t obj, const char *name, char *buf, size_t len);
/* Units of a dataset by name ("m", "m/s", "Pa", ...; "1" when unknown). */
const char *mf_h5_unit(const char *dataset);
/* Datasets every particle group has; anything else is an optional field. */
bool mf_h5_is_core_dataset(const char *name);

/* Attributes. `what` names the object in error messages (file:/group). The
 * attribute has n elements (n == 0: a scalar). */
int mf_h5_attr_write(hid_t obj, const char *name, hid_t file_type, hid_t mem_type, size_t n,
                     const void *buf, const char *what);
int mf_h5_attr_write_string(hid_t obj, const char *name, const char *value, const char *what);
/* Read an attribute that must hold exactly n elements (n == 0: scalar or 1). */
int mf_h5_attr_read(hid_t obj, const char *name, hid_t mem_type, size_t n, void *buf,
                    const char *what);

/* The names of the datasets directly in a group, in name order. *names is
 * malloc'ed (n entries of MF_H5_NAME_MAX); free it. */
int mf_h5_list_datasets(hid_t group, char (**names)[MF_H5_NAME_MAX], size_t *n,
                        const char *what);

/* Shape and type of a dataset: rows, components (1 for rank 1), and whether
 * it is a 32-bit integer, 64-bit integer or 64-bit float dataset. */
typedef struct mf_h5_shape {
    hsize_t rows;
    int ncomp;
    int rank;
    bool is_int;
    bool is_unsigned;
    int precision; /* bytes per element */
} mf_h5_shape;
int mf_h5_dataset_shape(hid_t dset, mf_h5_shape *s, const char *what);

/* ---- hdf5_files.c: the output folder ------------------------------------ */

int mf_h5_output_dir(const char *case_dir, char *buf, size_t len);
int mf_h5_snapshot_path(const char *output_dir, int index, char *buf, size_t len);
/* Indices of the files snapshot_<digits>.h5 in output_dir, ascending. A
 * missing folder is no snapshot. *indices is malloc'ed (NULL when n == 0). */
int mf_h5_scan_snapshots(const char *output_dir, int **indices, size_t *n);

/* ---- hdf5_params.c ---------------------------------------------------- */

/* Write a dictionary tree under `group`: sub-dictionaries as sub-groups,
 * other entries as string attributes. */
int mf_h5_write_dict(hid_t group, const mf_dict *d, const char *what);

/* ---- xdmf_index.c -------------------------------------------------------- */

typedef struct mf_xdmf_set {
    char name[MF_H5_NAME_MAX];
    char unit[32];                 /* the dataset's Units attribute ("" if none) */
    int ncomp;
    bool is_int, is_unsigned;
    int precision;
} mf_xdmf_set;

/* What the XDMF needs to know of one snapshot. */
typedef struct mf_xdmf_snap {
    int index;
    double time;
    int64_t n[MF_NKINDS];          /* 0: kind absent */
    bool point_index[MF_NKINDS];   /* the kind has PointIndex (the vertex cells) */
    size_t nsets[MF_NKINDS];
    mf_xdmf_set *sets[MF_NKINDS];  /* datasets of the kind, Coordinates included */
} mf_xdmf_snap;

typedef struct mf_xdmf_index {
    size_t n, cap;
    mf_xdmf_snap *snap;            /* ascending index */
} mf_xdmf_index;

/* Read the description of snapshot `index` from its file. */
int mf_xdmf_describe(const char *output_dir, int index, mf_xdmf_snap *s);
/* Add (or replace the entry with the same index); takes ownership of s. */
int mf_xdmf_index_add(mf_xdmf_index *x, mf_xdmf_snap *s);
/* Drop the entry of snapshot `index` (purgeWrite), if listed. */
void mf_xdmf_index_remove(mf_xdmf_index *x, int index);
/* Describe every readable snapshot of the folder (unreadable ones are left
 * out of the index: the reader skips them too). */
int mf_xdmf_index_scan(mf_xdmf_index *x, const char *output_dir);
/* Write <output_dir>/particles.xdmf (through a .tmp and a rename). */
int mf_xdmf_index_write(const mf_xdmf_index *x, const char *output_dir);
void mf_xdmf_index_free(mf_xdmf_index *x);

#endif
