/* navcam.c - the `navcam` program: `navcam COMMAND ...` runs the command's
 * own executable (libexec/navcam/navcam-COMMAND beside this program, as git
 * does), so each command loads only the libraries it uses and `navcam
 * --version` starts in a few milliseconds. Help and version only here; it
 * links nothing but the C library. */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/version.h"

static const char main_help[] =
    "Usage: navcam COMMAND [OPTIONS]\n"
    "\n"
    "NavCam emulates a spacecraft navigation camera: it ray-traces a planetary\n"
    "body from a camera pose and a Sun direction, in physical units.\n"
    "\n"
    "Commands:\n"
    "  render [SCENE.yaml] -o OUT   render one frame to an image file\n"
    "  expose CAMERA.yaml -o OUT    frames of a uniform radiance field through the camera model\n"
    "  serve [SCENE.yaml]           run the camera emulator (poses in, frames out)\n"
    "  replay TRAJ.csv              stream a trajectory to `navcam serve`\n"
    "  pose send ...                send one pose or trigger to `navcam serve`\n"
    "  scene                        print the built-in default scene (a starting point)\n"
    "  brdf --model NAME ...        evaluate a reflectance model (CSV in, CSV out)\n"
    "  bench accuracy [-o DIR]      error against time of the render methods (CSV, chart)\n"
    "  stars index STARS.DAT -o IX  NavCam's star index from a catalogue (stars in frames)\n"
    "  stars info IX                an index's stars by magnitude, and its load time\n"
    "  compare REAL RENDER          a real image against a render: errors, NCC, limb IoU, shift\n"
    "  texture IMAGE...             texture statistics: FAST corners, spectrum slope, gradients\n"
    "  batch TRAJ.csv -o DIR        render a trajectory to a dataset (resumable, shardable)\n"
    "  population [SCENE.yaml]      every boulder and crater a scene generates, as CSV\n"
    "\n"
    "Options:\n"
    "  -h, --help      this help; `navcam COMMAND --help` (or `navcam help COMMAND`) for a\n"
    "                  command\n"
    "  -V, --version   print the version\n"
    "\n"
    "Examples:\n"
    "  navcam render -o frame.png                       # built-in default scene\n"
    "  navcam scene > my.yaml && navcam render my.yaml -o f.exr --quantity iof\n"
    "  navcam render my.yaml -o f.fits --set camera.position_m=[0,-3000,0]\n"
    "\n"
    "Configuration keys and units: docs/config.md.\n";

static const char *const commands[] = {"render", "expose", "serve",   "replay",  "pose",  "scene",      "brdf",
                                       "bench",  "stars",  "compare", "texture", "batch", "population", NULL};

/* The command's executable: DIR/libexec/navcam (a build tree) or
 * DIR/../libexec/navcam (an installed tree), DIR being this program's. */
static int find_command(const char *cmd, char *path, size_t len)
{
    char self[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        return -1;
    self[n] = '\0';
    char *slash = strrchr(self, '/');
    if (!slash)
        return -1;
    *slash = '\0';
    static const char *const dirs[] = {"%s/libexec/navcam/navcam-%s", "%s/../libexec/navcam/navcam-%s"};
    for (int i = 0; i < 2; i++) {
        snprintf(path, len, dirs[i], self, cmd);
        if (access(path, X_OK) == 0)
            return 0;
    }
    return -1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(main_help, stderr);
        return 2;
    }
    const char *cmd = argv[1];
    char **args = argv + 1, *help_args[3] = {NULL, "--help", NULL};
    if (!strcmp(cmd, "help") && argc > 2) /* navcam help COMMAND: the command's --help */
        cmd = argv[2], args = help_args;
    else if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        fputs(main_help, stdout);
        return 0;
    }
    if (!strcmp(cmd, "-V") || !strcmp(cmd, "--version")) {
        printf("navcam %s\n", NC_VERSION_STRING);
        return 0;
    }
    for (int i = 0; commands[i]; i++) {
        if (strcmp(cmd, commands[i]))
            continue;
        char path[PATH_MAX + 64];
        if (find_command(cmd, path, sizeof path) < 0) {
            fprintf(stderr, "navcam: the '%s' command is not installed beside this program (libexec/navcam/navcam-%s)\n",
                    cmd, cmd);
            return 127;
        }
        /* argv[0] of the command is "navcam COMMAND", which getopt's
         * messages then begin with */
        char prog[96];
        snprintf(prog, sizeof prog, "navcam %s", cmd);
        args[0] = prog;
        execv(path, args);
        fprintf(stderr, "navcam: %s: %s\n", path, strerror(errno));
        return 126;
    }
    fprintf(stderr, "navcam: unknown %s '%s'\n\n%s", cmd[0] == '-' ? "option" : "command", cmd, main_help);
    return 2;
}
