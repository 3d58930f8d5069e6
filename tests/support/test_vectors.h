/* Reading committed reference vectors (tests/vectors/NAME.csv, written by tools/ scripts
 * from scipy/numpy). Header-only; test code may allocate, firmware never does. */
#ifndef TEST_VECTORS_H
#define TEST_VECTORS_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Load a CSV of numbers (lines starting with '#' are comments) from tests/vectors/NAME.
 * Returns a malloc'd row-major array of rows*cols doubles, or NULL with a message. */
static inline double *tv_load_csv(const char *name, size_t *rows, size_t *cols)
{
  char path[512];
  snprintf(path, sizeof path, "%s/%s", GYRO_TEST_VECTORS_DIR, name);
  FILE *f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "cannot open test vector %s\n", path);
    return NULL;
  }
  size_t cap = 1024, n = 0, ncols = 0;
  double *data = malloc(cap * sizeof *data);
  char line[8192];
  *rows = 0;
  while (data && fgets(line, sizeof line, f)) {
    if (line[0] == '#' || line[0] == '\n') continue;
    size_t c = 0;
    char *p = line;
    for (;;) {
      char *end;
      double v = strtod(p, &end);
      if (end == p) break;
      if (n == cap) {
        cap *= 2;
        double *grown = realloc(data, cap * sizeof *data);
        if (!grown) {
          free(data);
          data = NULL;
          break;
        }
        data = grown;
      }
      data[n++] = v;
      c++;
      p = end;
      while (*p == ',' || *p == ' ' || *p == '\t') p++;
    }
    if (!data) break;
    if (ncols == 0) ncols = c;
    if (c != ncols) {
      fprintf(stderr, "%s: ragged row %zu\n", path, *rows + 1);
      free(data);
      data = NULL;
      break;
    }
    (*rows)++;
  }
  fclose(f);
  *cols = ncols;
  return data;
}

#endif /* TEST_VECTORS_H */
