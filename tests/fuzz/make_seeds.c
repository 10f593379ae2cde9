/* make_seeds.c - the protocol fuzzer's seed corpus: one valid message of
 * every flag combination, one file each, into the directory argv[1]. */
#include <stdio.h>

#include "navcam/protocol.h"

int main(int argc, char **argv)
{
    if (argc != 2)
        return 2;
    for (unsigned f = 0; f <= NC_MSG_KNOWN_FLAGS; f++) {
        /* odd f a TRIGGER, without the pose's block flags it cannot take */
        const int trigger = f & 1;
        struct nc_pose_msg m = {.type = trigger ? NC_MSG_TRIGGER : NC_MSG_POSE, .sequence = f,
                                .flags = trigger ? f & ~NC_MSG_POSE_ONLY_FLAGS : f};
        m.cam_attitude_q = m.body_attitude_q = (struct nc_quat){1, 0, 0, 0};
        m.sun = (struct nc_vec3){1, 0, 0};
        unsigned char b[NC_PROTO_MAX_BYTES];
        size_t n = nc_msg_encode(&m, b, sizeof b);
        char path[4096];
        snprintf(path, sizeof path, "%s/seed_%03u", argv[1], f);
        FILE *fp = fopen(path, "wb");
        if (!fp || fwrite(b, 1, n, fp) != n)
            return 1;
        fclose(fp);
    }
    return 0;
}
