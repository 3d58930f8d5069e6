#include "post.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef GYRO_TOOLS_DIR
#error "GYRO_TOOLS_DIR: the tools/ folder, set by CMake"
#endif

static char *read_all(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL) return NULL;
  fseek(f, 0, SEEK_END);
  const long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *b = n >= 0 ? malloc((size_t)n + 1u) : NULL;
  if (b != NULL) {
    const size_t r = fread(b, 1, (size_t)n, f);
    b[r] = '\0';
  }
  fclose(f);
  return b;
}

cJSON *post_run_tool(const char *tool, const char *const *args, const char *out_dir,
                     const char *json_name, char *err, size_t err_len)
{
  char exe[1024];
  snprintf(exe, sizeof exe, "%s/%s", GYRO_TOOLS_DIR, tool);
  char *argv[40];
  char out_copy[1024];
  snprintf(out_copy, sizeof out_copy, "%s", out_dir);
  char arg_copy[36][512];
  int n = 0;
  argv[n++] = exe;
  for (int i = 0; args[i] != NULL && n < 36; i++) {
    snprintf(arg_copy[i], sizeof arg_copy[i], "%s", args[i]);
    argv[n++] = arg_copy[i];
  }
  static char out_flag[] = "--out";
  argv[n++] = out_flag;
  argv[n++] = out_copy;
  argv[n] = NULL;
  char logpath[1024];
  snprintf(logpath, sizeof logpath, "%s/%s.log", out_dir, tool);
  fflush(NULL);
  const pid_t pid = fork();
  if (pid < 0) {
    snprintf(err, err_len, "%s: fork: %s", tool, strerror(errno));
    return NULL;
  }
  if (pid == 0) {
    FILE *lf = freopen(logpath, "w", stdout);
    if (lf != NULL) dup2(fileno(stdout), 2);
    execv(exe, argv);
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    char *log = read_all(logpath);
    snprintf(err, err_len, "%s failed (exit %d): %.300s", tool,
             WIFEXITED(status) ? WEXITSTATUS(status) : -1, log ? log : "");
    free(log);
    return NULL;
  }
  char jpath[1024];
  snprintf(jpath, sizeof jpath, "%s/%s", out_dir, json_name);
  char *txt = read_all(jpath);
  cJSON *j = txt ? cJSON_Parse(txt) : NULL;
  free(txt);
  if (j == NULL) snprintf(err, err_len, "%s: no readable %s", tool, jpath);
  return j;
}

double post_num(const cJSON *root, const char *path)
{
  char buf[256];
  snprintf(buf, sizeof buf, "%s", path);
  const cJSON *cur = root;
  for (char *tok = strtok(buf, "."); tok != NULL && cur != NULL; tok = strtok(NULL, ".")) {
    cur = cJSON_GetObjectItemCaseSensitive(cur, tok);
  }
  return cJSON_IsNumber(cur) ? cur->valuedouble : NAN;
}
