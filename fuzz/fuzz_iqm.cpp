// libFuzzer target: any bytes → a .iqm file → animorder::load_iqm.
#include "loader_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = animorder_fuzz::write_input(data, size, "input.iqm");
    animorder_fuzz::run_loader(
        [](const std::string& p, const animorder::LoadOptions& o) { return animorder::load_iqm(p, o); }, path);
    return 0;
}
