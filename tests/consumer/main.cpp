// A consumer of the installed library (tests/consumer/run.sh): `single` on the bundled procedural
// character, with the settings run.sh gives the installed tool too, written as the sidecar the
// tool writes; run.sh compares the two files byte for byte.
#include "animorder/atomic_write.h"
#include "animorder/invalid_input.h"
#include "animorder/methods.h"
#include "animorder/procedural_character.h"
#include "animorder/sidecar.h"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: consumer OUT.animorder.bin\n");
        return 2;
    }
    try {
        const animorder::AnimatedMesh mesh = animorder::make_procedural_character();
        animorder::MethodSettings settings;
        settings.clustering.clusters = 2;
        settings.clustering.views = 12;
        settings.clustering.resolution = 32;
        settings.clustering.max_iterations = 2;
        const animorder::MethodResult r = animorder::run_method(mesh, animorder::Method::Single, settings);
        animorder::OutputSet out;
        out.add(argv[1], animorder::serialize_sidecar(mesh, r.buffers, r.framing));
        out.commit();
        std::printf("animorder %s: %zu triangles, %zu buffers, ACMR %.4f\n", animorder::library_version(),
                    mesh.triangle_count(),
                    r.buffers.orders.size(), r.acmr_mean);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "consumer: %s\n", e.what());
        return 1;
    }
    return 0;
}
