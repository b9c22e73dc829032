/* A tiny SDI-12 v1.3 data logger, written for the host against logger_bus.h. */
#ifndef TINY_LOGGER_H
#define TINY_LOGGER_H

/* Do one job of the recorder suite: TASK is "measure", "concurrent", "command" or
 * "transparent", CMDS the commands as wire text ("0M!"). Returns NULL when done, or a short
 * reason when this logger cannot do the job. */
const char *logger_job(const char *task, char *const cmds[], int n);

#endif
