/* pm_keys: the scene vocabulary as tables of keys.  Each key is declared
 * once, where the code that owns it lives: its name, type, where its value
 * goes, its default, its range, its unit and a line of documentation.  One
 * reader (src/common/scene/pm_reader.h) checks a YAML tree against the
 * tables and fills the target structs; error messages ("FILE:LINE:COL: KEY:
 * expected ..., got ...") and `pointmech keys` come from the same tables.
 * This header holds declarations only, so that every layer can declare its
 * keys (constitutive models, backend sections) without the reader. */
#ifndef PM_KEYS_H
#define PM_KEYS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "pm_error.h"

typedef enum {
  PM_KEY_END = 0,    /* terminates a table */
  PM_KEY_NUMBER,     /* double */
  PM_KEY_INTEGER,    /* long */
  PM_KEY_BOOL,       /* bool */
  PM_KEY_STRING,     /* char *, owned by the target (freed with it) */
  PM_KEY_ENUM,       /* int: the value of one of `names` */
  PM_KEY_FLAGS,      /* unsigned: the OR of the values of a list of names */
  PM_KEY_EXPR,       /* pm_expr *, owned: an expression (a number is one) */
  PM_KEY_COMPONENTS, /* {x, y, z} of expressions: pm_expr *[3] at offset,
                        unsigned mask of those given at count_offset; z is
                        refused in 2D */
  PM_KEY_POINT,      /* double[3]: exactly `dimension` numbers (z 0 in 2D) */
  PM_KEY_NUMBERS,    /* double[max_count]: min_count..max_count numbers,
                        their number (int) at count_offset */
  PM_KEY_MAPPING,    /* nested keys; their offsets add to this one's */
  PM_KEY_LIST,       /* list of mappings of `keys`: an owned array of
                        elem_size-byte elements at offset (void *), their
                        number (int) at count_offset */
  PM_KEY_CUSTOM      /* read by the key's read function */
} pm_key_type;

/* Range of a NUMBER, INTEGER or NUMBERS key (bit mask; 0: any value). */
enum {
  PM_RANGE_GE = 1u << 0, /* value >= lo */
  PM_RANGE_GT = 1u << 1, /* value > lo */
  PM_RANGE_LE = 1u << 2, /* value <= hi */
  PM_RANGE_LT = 1u << 3  /* value < hi */
};

/* Other flags. */
enum {
  PM_KEY_REQUIRED = 1u << 0, /* must be present (def is then unused) */
  PM_KEY_NO_T = 1u << 1,     /* EXPR / COMPONENTS: x, y, z only (no t) */
  PM_KEY_NO_XYZ = 1u << 2,   /* EXPR / COMPONENTS: t only */
  PM_KEY_WHOLE = 1u << 3     /* NUMBERS: whole numbers only */
};

/* A name of an ENUM or FLAGS key and its value; tables end with {NULL}. */
typedef struct {
  const char *name;
  int value;
} pm_name;

typedef struct pm_reader pm_reader;
typedef struct pm_key pm_key;

/* A CUSTOM key's reader: read the node `id` found at `path` into the
 * target at dst (the key's offset already added).  Fails with PM_ERR_SCENE
 * through pm_reader_fail / pm_reader_expected. */
typedef pm_err (*pm_key_read_fn)(pm_reader *r, int id, const char *path,
                                 const pm_key *key, void *dst);

struct pm_key {
  const char *name;
  pm_key_type type;
  size_t offset;              /* of the value in the target struct */
  const char *def;            /* default, as scene text ("20", "iipg", "[2]",
                                 "nan"); NULL: optional with no default (the
                                 target keeps its zero; presence can be asked) */
  unsigned flags;             /* PM_KEY_* */
  unsigned range;             /* PM_RANGE_* */
  double lo, hi;              /* range bounds */
  const pm_name *names;       /* ENUM, FLAGS */
  const pm_key *keys;         /* MAPPING, LIST */
  size_t elem_size;           /* LIST */
  size_t count_offset;        /* COMPONENTS (mask), NUMBERS, LIST (count) */
  int min_count, max_count;   /* NUMBERS, LIST, FLAGS (0: no bound) */
  pm_key_read_fn read;        /* CUSTOM */
  void (*release)(void *dst); /* CUSTOM: free what read allocated (may be
                                 NULL) */
  const char *what;           /* CUSTOM: what it takes ("2 or 3") */
  const char *unit;           /* SI unit ("Pa", "m", "1/s"; "" none) */
  const char *doc;            /* one line for `pointmech keys` */
};

/* The key of table keys named name, or NULL. */
const pm_key *pm_key_find(const pm_key *keys, const char *name);

/* Names of an ENUM table joined by ", " into buf ("iipg, sipg"). */
void pm_key_names(const pm_name *names, char *buf, size_t size);

/* The name of value v in names, or "?". */
const char *pm_key_name_of(const pm_name *names, int v);

/* What a value of key k must be, for "expected ..." messages: "a number >
 * 0", "one of iipg, sipg", "2 or 3 numbers", ... */
void pm_key_describe(const pm_key *k, char *buf, size_t size);

/* Whether v is in k's range. */
bool pm_key_in_range(const pm_key *k, double v);

/* Print a table for readers: one entry per key (prefix.name, its meaning,
 * then what it takes, its unit and default), nested tables after their
 * key. */
void pm_key_print(FILE *out, const pm_key *keys, const char *prefix);

#endif
