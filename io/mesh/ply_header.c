/* ply_header.c: a strict check of a PLY file's header before assimp reads
 * it. Debian's assimp 5.2 spends minutes (sanitizers: a timeout; release:
 * over two minutes, still running) in its PLY reader on a header with a
 * misspelt keyword and NUL bytes (found by fuzz_mesh, in its corpus), and
 * allocates from element counts the file cannot hold. The header grammar is
 * small (Turk's PLY format, as paulbourke.net/dataformats/ply gives it), so
 * it is checked here, line by line, with the counts against the file's size.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mf_error.h"
#include "mf_mesh_import.h"

#define PLY_MAX_HEADER 65536
#define PLY_MAX_ELEMENTS 64
#define PLY_MAX_PROPERTIES 256

/* Bytes of a PLY scalar type, 0 if the word is none. */
static int type_size(const char *t)
{
    static const struct {
        const char *name;
        int size;
    } types[] = {{"char", 1},   {"uchar", 1},   {"short", 2},   {"ushort", 2},  {"int", 4},
                 {"uint", 4},   {"float", 4},   {"double", 8},  {"int8", 1},    {"uint8", 1},
                 {"int16", 2},  {"uint16", 2},  {"int32", 4},   {"uint32", 4},  {"float32", 4},
                 {"float64", 8}};
    for (size_t k = 0; k < sizeof types / sizeof types[0]; k++)
        if (strcmp(t, types[k].name) == 0)
            return types[k].size;
    return 0;
}

typedef struct {
    unsigned long long count;
    size_t min_bytes; /* smallest binary record: scalars, and list counts */
    size_t nvalues;   /* values of an ASCII record, at least (a list: its count) */
} ply_element;

int mf_ply_check_header(const char *path, size_t file_bytes)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return MF_ERROR(MF_ERR_IO, "%s: cannot open (%s)", path, strerror(errno));
    char *buf = malloc(PLY_MAX_HEADER + 1);
    if (!buf) {
        fclose(f);
        return MF_ERROR(MF_ERR_MEMORY, "out of memory reading %s", path);
    }
    size_t got = fread(buf, 1, PLY_MAX_HEADER, f);
    fclose(f);
    buf[got] = '\0';
    int rc = 0, ascii = 0, nel = 0;
    ply_element el[PLY_MAX_ELEMENTS];
    size_t line = 0, pos = 0, header_end = 0;
    bool ended = false;
    while (rc == 0 && !ended) {
        char *nl = memchr(buf + pos, '\n', got - pos);
        if (!nl) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s: PLY header without end_header in its first %d bytes",
                          path, PLY_MAX_HEADER);
            break;
        }
        size_t len = (size_t)(nl - (buf + pos));
        line++;
        if (memchr(buf + pos, '\0', len)) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: PLY header line holds a NUL byte", path, line);
            break;
        }
        char text[512];
        if (len >= sizeof text) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: PLY header line longer than %zu characters", path,
                          line, sizeof text - 1);
            break;
        }
        memcpy(text, buf + pos, len);
        text[len] = '\0';
        if (len && text[len - 1] == '\r')
            text[len - 1] = '\0';
        pos += len + 1;
        char w[4][64];
        int nw = sscanf(text, "%63s %63s %63s %63s", w[0], w[1], w[2], w[3]);
        if (line == 1) {
            if (nw != 1 || strcmp(w[0], "ply") != 0)
                rc = MF_ERROR(MF_ERR_INPUT, "%s:1: a PLY file starts with the line 'ply'", path);
            continue;
        }
        if (nw < 1) {
            rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: empty PLY header line", path, line);
        } else if (strcmp(w[0], "comment") == 0 || strcmp(w[0], "obj_info") == 0) {
            /* free text */
        } else if (strcmp(w[0], "format") == 0) {
            if (nw != 3 || strcmp(w[2], "1.0") != 0 ||
                (strcmp(w[1], "ascii") && strcmp(w[1], "binary_little_endian") &&
                 strcmp(w[1], "binary_big_endian")))
                rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: expected 'format ascii|binary_little_endian|"
                              "binary_big_endian 1.0'", path, line);
            ascii = strcmp(w[1], "ascii") == 0;
        } else if (strcmp(w[0], "element") == 0) {
            char *end = NULL;
            unsigned long long count = nw == 3 ? strtoull(w[2], &end, 10) : 0;
            if (nw != 3 || !end || *end || w[2][0] == '-')
                rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: expected 'element NAME COUNT'", path, line);
            else if (nel == PLY_MAX_ELEMENTS)
                rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: more than %d elements", path, line,
                              PLY_MAX_ELEMENTS);
            else
                el[nel++] = (ply_element){count, 0, 0};
        } else if (strcmp(w[0], "property") == 0) {
            if (nel == 0) {
                rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: a property before any element", path, line);
            } else if (nw == 3 && type_size(w[1])) {
                el[nel - 1].min_bytes += (size_t)type_size(w[1]);
                el[nel - 1].nvalues++;
            } else if (nw == 4 && strcmp(w[1], "list") == 0) {
                char name[64];
                int n2 = sscanf(text, "%*s %*s %*s %*s %63s", name);
                if (n2 != 1 || !type_size(w[2]) || !type_size(w[3]))
                    rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: expected 'property list COUNTTYPE "
                                  "TYPE NAME'", path, line);
                el[nel - 1].min_bytes += (size_t)type_size(w[2]);
                el[nel - 1].nvalues++;
            } else {
                rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: expected 'property TYPE NAME' or 'property "
                              "list COUNTTYPE TYPE NAME' (types: char uchar short ushort int uint "
                              "float double, or int8 ... float64)", path, line);
            }
            if (rc == 0 && el[nel - 1].nvalues > PLY_MAX_PROPERTIES)
                rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: more than %d properties", path, line,
                              PLY_MAX_PROPERTIES);
        } else if (strcmp(w[0], "end_header") == 0 && nw == 1) {
            ended = true;
            header_end = pos;
        } else {
            rc = MF_ERROR(MF_ERR_INPUT, "%s:%zu: '%s' is not a PLY header keyword (ply, format, "
                          "comment, obj_info, element, property, end_header)", path, line, w[0]);
        }
    }
    free(buf);
    MF_CALL(rc);
    /* The records must fit the bytes after the header: an ASCII value takes
     * at least two (a digit and a separator). */
    const double left = (double)(file_bytes - header_end);
    double need = 0;
    for (int e = 0; e < nel; e++)
        need += (double)el[e].count *
                (ascii ? 2.0 * (double)el[e].nvalues : (double)el[e].min_bytes);
    if (need > left)
        return MF_ERROR(MF_ERR_INPUT, "%s: the PLY header's elements need at least %.0f bytes, "
                        "the file holds %.0f after its header (a cut file, or wrong counts)",
                        path, need, left);
    return 0;
}
