/* Post-processing of a gyro-sim trace by the analysis tools (tools/gyro-*): each
 * spectral, Allan or fit figure is implemented once, in Python with numpy/scipy/
 * allantools, and read back from the tool's JSON. */
#ifndef SIM_POST_H
#define SIM_POST_H

#include <cJSON.h>
#include <stddef.h>

/* Run tools/<tool> with args (NULL-terminated) writing into out_dir, then parse
 * out_dir/<json_name>. Returns the parsed JSON (caller frees) or NULL with err set. */
cJSON *post_run_tool(const char *tool, const char *const *args, const char *out_dir,
                     const char *json_name, char *err, size_t err_len);

/* A number at a dotted path ("p_fit.residual_std_dps") or NAN. */
double post_num(const cJSON *root, const char *path);

#endif /* SIM_POST_H */
