/* Parameter store: persistent parameters in two flash sectors (slots A and B) used in
 * turn, so that a power cut at any byte of a save leaves the previous image loadable.
 *
 * Image (little-endian, every field 4-byte aligned; see "Programming unit" below):
 *
 *   offset      size  field
 *   0           4     magic       0x4D524750 ("PGRM" in byte order)
 *   4           2     format      1: this header and record encoding
 *   6           2     layout      PARAM_LAYOUT_VERSION of the writer (diagnostic only)
 *   8           4     fw_version  writer's firmware, MAJOR << 16 | MINOR << 8 | PATCH
 *   12          4     seq         save counter; the newer of two valid images wins
 *                                 (serial-number comparison, so a wrap is harmless)
 *   16          4     count       number of records n
 *   20          8n    records     {u16 id, u8 type (param_type_t), u8 0, u32 value}
 *                                 value: IEEE-754 bits for F32, the integer otherwise
 *   20+8n       4     crc         CRC-32 (crc32.h) of bytes [0, 20+8n)
 *   24+8n       4     commit      0x5AFEC0DE, programmed last
 *
 * Programming unit (hal_flash_geometry's program_bytes, a power of two up to
 * PARAM_STORE_PROGRAM_MAX): header, records and crc end at 24+8n, a multiple of 8, so
 * they are programmed as whole units in one call, and the commit word starts a unit of
 * its own; with a unit wider than the commit word (8 bytes: ECC flash that programs
 * 64-bit double words) the rest of its unit is programmed as 0xFF, which no loader
 * reads. The image layout is the same for every unit, so an image written with 32-bit
 * programming loads on a part with 64-bit programming and back.
 *
 * Save: refuse unless the loop is in a safe mode (see below); encode; if the newest
 * valid image holds exactly these records, write nothing (PARAM_STORE_UNCHANGED);
 * otherwise erase the other slot, program header + records + crc, then the commit word,
 * then read back and validate. Until the commit word is complete the new slot is
 * invalid (an erased or torn commit word never equals 0x5AFEC0DE, which has no 0xFF
 * byte), and the old slot is never touched, so every cut leaves old or new.
 *
 * Load: an image is valid when magic, format, count (fits in the sector), commit word
 * and CRC all check. The valid image with the higher seq wins; a corrupt newest image
 * falls back to the other slot. Records are migrated field by field against the running
 * table: unknown (or no longer persistent) ids are dropped and counted; a wrong type or
 * a value failing param_check is rejected and counted, and that parameter keeps its
 * default; an id that appears more than once is a duplicate: all its records are
 * rejected (which one was meant cannot be told) and it keeps its default as well;
 * persistent parameters missing from the image take their defaults. A float -0 loads as
 * +0 (param_put). With no valid image, nothing is loaded and the caller keeps its
 * values (defaults at boot), with the slot states in the report.
 *
 * An image of a newer format (magic right, format above PARAM_STORE_FORMAT and below
 * 0x100: a set high byte is an erased or torn field) is not read,
 * and not overwritten either: a save that would erase it is refused
 * (PARAM_STORE_ERR_NEWER) while either slot holds one (the next save would take the
 * other slot), unless the caller forces it (PARAM_SAVE_FORCE); a forced save still
 * writes the slot without it when it can.
 *
 * Why save needs the loop safe: on a single-bank part a 16 KB sector erase stalls
 * every instruction fetch from flash for 250 ms typical (500 ms max), and the drive
 * amplitude decays with tau = 2 Q1 / wn1 = 7 ms (6-12). The flash routines, the vector
 * table, the UART interrupt and the sample interrupt's path in LOCKED (and the SWEEP
 * executive) run from SRAM, so a LOCKED tick survives an erase; but the rest does not:
 * sample-path code of the other modes and of a mode change, and the background loop
 * (supervisor requests, parameter publication, telemetry drain, command line) stop for
 * up to ~70 time constants, and telemetry frames are dropped. So a save is refused
 * unless the caller says the loop is safe (params_loop_safe: drive OFF once the queued
 * requests are applied, no self-calibration running).
 */
#ifndef PARAM_STORE_H
#define PARAM_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "params/params.h"

#define PARAM_STORE_MAGIC 0x4D524750u
#define PARAM_STORE_FORMAT 1u
#define PARAM_STORE_COMMIT 0x5AFEC0DEu
#define PARAM_STORE_HDR_BYTES 20u
#define PARAM_STORE_REC_BYTES 8u
/* Largest image this firmware writes: every parameter persistent. */
#define PARAM_STORE_IMAGE_MAX (PARAM_STORE_HDR_BYTES + PARAM_STORE_REC_BYTES * PARAM_COUNT + 8u)
/* Widest programming unit the layout serves (header + records + crc is a multiple of 8). */
#define PARAM_STORE_PROGRAM_MAX 8u
/* Largest record count a loader accepts (bounded further by the sector size). */
#define PARAM_STORE_MAX_RECORDS 4096u

typedef enum {
  PARAM_STORE_OK = 0,
  PARAM_STORE_UNCHANGED,  /* save: the newest image already holds these values */
  PARAM_STORE_NONE,       /* load: no valid image; nothing loaded */
  PARAM_STORE_ERR_BUSY,   /* save refused: the loop is not in a safe mode */
  PARAM_STORE_ERR_FLASH,  /* erase/program failed (including a power cut) */
  PARAM_STORE_ERR_VERIFY, /* the written image did not read back valid */
  PARAM_STORE_ERR_CONFIG, /* bad sectors or a sector too small for an image */
  PARAM_STORE_NEWER,      /* load: no valid image, but one of a newer format */
  PARAM_STORE_ERR_NEWER   /* save refused: it would erase a newer-format image */
} param_store_status_t;

/* How a save may go (bits). */
enum {
  PARAM_SAVE_LOOP_SAFE = 1u << 0, /* the caller's word that the loop is in a safe mode */
  PARAM_SAVE_FORCE = 1u << 1      /* overwrite a newer-format image if need be */
};

typedef enum {
  PARAM_SLOT_EMPTY = 0, /* header erased (all 0xFF) */
  PARAM_SLOT_VALID,
  PARAM_SLOT_CORRUPT, /* something there, but it does not check */
  PARAM_SLOT_NEWER    /* an image of a newer format: not read, not overwritten */
} param_slot_state_t;

typedef struct {
  uint32_t sector_a; /* hal_flash sector numbers of the two slots */
  uint32_t sector_b;
} param_store_cfg_t;

typedef struct {
  uint32_t sector[2];
  uint32_t sector_size;
  uint32_t program_bytes; /* the flash's programming unit (hal_flash_geometry) */
  /* encode buffer: the image, then the commit word's unit filled up with 0xFF */
  uint8_t buf[PARAM_STORE_IMAGE_MAX - 4u + PARAM_STORE_PROGRAM_MAX];
} param_store_t;

typedef struct {
  uint8_t slot_state[2]; /* param_slot_state_t of A and B at the time of the call */
  int8_t slot;           /* slot loaded or written (0 = A, 1 = B), -1 none */
  uint32_t seq;          /* its sequence number */
  uint32_t fw_version;   /* load: writer's firmware version */
  uint16_t layout;       /* load: writer's PARAM_LAYOUT_VERSION */
  uint16_t dropped;      /* load: records with unknown or non-persistent ids */
  uint16_t rejected;     /* load: records with a bad type, duplicate id or bad value */
  uint16_t defaulted;    /* load: persistent parameters missing from the image */
} param_store_report_t;

param_store_status_t param_store_init(param_store_t *st, const param_store_cfg_t *cfg);

/* Load the newest valid image into *v: every persistent parameter is overwritten (from
 * the image or its default); other members are left as the caller set them. Returns
 * PARAM_STORE_OK, or PARAM_STORE_NONE / PARAM_STORE_NEWER with *v untouched. Never
 * writes flash. */
param_store_status_t param_store_load(param_store_t *st, param_values_t *v,
                                      param_store_report_t *rep);

/* Save the persistent parameters of *v (all must pass param_check). how: PARAM_SAVE_*
 * bits; without PARAM_SAVE_LOOP_SAFE -> PARAM_STORE_ERR_BUSY, and a save that would erase
 * a newer-format image without PARAM_SAVE_FORCE -> PARAM_STORE_ERR_NEWER, both without
 * touching flash. */
param_store_status_t param_store_save(param_store_t *st, const param_values_t *v, uint32_t how,
                                      param_store_report_t *rep);

const char *param_store_status_str(param_store_status_t s);

#endif /* PARAM_STORE_H */
