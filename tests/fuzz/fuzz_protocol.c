/* fuzz_protocol.c - libFuzzer target: the pose-message decoder on arbitrary
 * bytes. It must never crash or read out of bounds, and anything it accepts
 * must re-encode to the same length. */
#include <stdint.h>
#include <stdlib.h>

#include "navcam/protocol.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct nc_pose_msg m;
    if (nc_msg_decode(data, size, &m) == NC_REJECT_NONE) {
        uint8_t buf[NC_PROTO_MAX_BYTES];
        if (nc_msg_encode(&m, buf, sizeof buf) != size)
            abort();
    }
    return 0;
}
