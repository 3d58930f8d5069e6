/* Firmware parameter sets: a part's calibration (its persistent firmware parameters) as
 * a JSON file that the host loads into the firmware as if from flash. Format version 1,
 * described in docs/param-set.md:
 *
 *   {
 *     "format": "gyro-param-set",
 *     "format_version": 1,
 *     "layout_version": 5,             PARAM_LAYOUT_VERSION of the writer (informational)
 *     "firmware": "0.1.0",             the writer's firmware version (informational)
 *     "meta": { ... },                 free-form: part, date, command, notes (not checked)
 *     "params": [ {"id": "0x0101", "name": "drive.freq_hz", "value": 1489.9}, ... ],
 *     "crc32": "0x1234abcd"
 *   }
 *
 * Only the listed parameters are set; the others keep the values the caller starts from
 * (the defaults, as flash leaves them). Each entry is checked against the running table
 * (params.h), which is all this module knows of the parameters, so a new row needs no
 * change here: a known id, its name, a persistent and writable parameter, no duplicate,
 * a number of the right kind (an integer for U32/ENUM), param_check. The crc32 is
 * CRC-32/IEEE (crc32.h, = zlib.crc32) of the lines "%04x %08x\n" (id, value bits: the
 * float32 pattern of an F32 value, the integer otherwise) in file order. The set is then
 * designed as a whole (gyro_design, what the application's commit runs), so values that
 * pass one by one but not together are refused too. A set is taken whole or not at all.
 */
#ifndef PARAM_SET_H
#define PARAM_SET_H

#include <stddef.h>
#include <stdint.h>

#include "params/params.h"

#define PARAM_SET_FORMAT "gyro-param-set"
#define PARAM_SET_FORMAT_VERSION 1u
/* Largest file param_set_load_file reads. */
#define PARAM_SET_FILE_MAX ((size_t)1u << 20)

/* What a parsed file said about itself (informational fields; -1 / "" when absent). */
typedef struct {
  uint32_t format_version;
  long layout_version;
  char firmware[32];
  unsigned count; /* entries applied */
} param_set_meta_t;

/* Parse a parameter set (JSON text) and apply it onto *v_inout. Returns 0; or -1 with a
 * one-line message in err that names the entry and why, and *v_inout unchanged.
 * meta_opt may be NULL. */
int param_set_parse(const char *json, param_values_t *v_inout, param_set_meta_t *meta_opt,
                    char *err, size_t err_len);

/* param_set_parse of a file (at most PARAM_SET_FILE_MAX bytes); messages start with the
 * path. */
int param_set_load_file(const char *path, param_values_t *v_inout, param_set_meta_t *meta_opt,
                        char *err, size_t err_len);

/* The parameter set of every persistent, writable parameter of *v (table order), with
 * meta_json (a JSON object as text, or NULL: none) as its "meta". Returns the text
 * (malloc'd, the caller frees), or NULL with err (a value failing param_check, meta not
 * an object, out of memory). */
char *param_set_format(const param_values_t *v, const char *meta_json, char *err, size_t err_len);

/* param_set_format into a file (written beside it, then renamed over it). Returns 0, or -1
 * with err. */
int param_set_write_file(const char *path, const param_values_t *v, const char *meta_json,
                         char *err, size_t err_len);

/* The checksum line of one value: "%04x %08x\n" of id and bits. */
void param_set_crc_line(uint16_t id, uint32_t bits, char out[16]);

#endif /* PARAM_SET_H */
