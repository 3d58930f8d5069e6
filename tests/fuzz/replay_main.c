/* Plain driver for a fuzz harness: runs LLVMFuzzerTestOneInput over every file of a
 * corpus directory (and the empty input), so saved corpora and crash reproducers are
 * regression tests in the normal ctest run, without libFuzzer. */
#define _DEFAULT_SOURCE /* dirent */
#include <dirent.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int run_file(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL) {
    return -1;
  }
  size_t cap = 4096, n = 0;
  uint8_t *buf = malloc(cap);
  size_t got;
  while (buf != NULL && (got = fread(buf + n, 1, cap - n, f)) > 0) {
    n += got;
    if (n == cap) {
      cap *= 2;
      uint8_t *nb = realloc(buf, cap);
      if (nb == NULL) {
        free(buf);
        buf = NULL;
      }
      buf = nb;
    }
  }
  fclose(f);
  if (buf == NULL) {
    return -1;
  }
  LLVMFuzzerTestOneInput(buf, n);
  free(buf);
  return 0;
}

int main(int argc, char **argv)
{
  if (argc != 2) {
    fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
    return 2;
  }
  LLVMFuzzerTestOneInput((const uint8_t *)"", 0);
  DIR *d = opendir(argv[1]);
  if (d == NULL) {
    fprintf(stderr, "%s: no corpus directory\n", argv[1]);
    return 1;
  }
  unsigned count = 0;
  const struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.') {
      continue;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", argv[1], e->d_name);
    if (run_file(path) != 0) {
      fprintf(stderr, "%s: cannot read\n", path);
      closedir(d);
      return 1;
    }
    count++;
  }
  closedir(d);
  printf("%u corpus inputs replayed from %s\n", count, argv[1]);
  return 0;
}
