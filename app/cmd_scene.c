/* cmd_scene.c - `navcam scene`: print the built-in default scene. */
#include <stdio.h>
#include <string.h>

#include "render/scene.h"

int main(int argc, char **argv)
{
    if (argc > 1 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help"))) {
        puts("Usage: navcam scene\n\nPrint the built-in default scene as YAML, to copy and edit.");
        return 0;
    }
    if (argc > 1) {
        fprintf(stderr, "navcam scene: takes no arguments\n");
        return 2;
    }
    fputs(nc_default_scene_yaml, stdout);
    return 0;
}
