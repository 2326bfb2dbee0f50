/* Root isolation by sturm: not written yet; selecting it fails at kernel build time. */
#ifndef ALGRAY_STURM_H
#define ALGRAY_STURM_H
#error "this isolation method is not written yet"
#endif
