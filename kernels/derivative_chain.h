/* Root isolation by derivative_chain: not written yet; selecting it fails at kernel build time. */
#ifndef ALGRAY_DERIVATIVE_CHAIN_H
#define ALGRAY_DERIVATIVE_CHAIN_H
#error "this isolation method is not written yet"
#endif
