/* The project's tiny logger, compiled into the sketch as it is (see sdi12_logger.ino). */
#include "../../c/tiny_logger.c"
