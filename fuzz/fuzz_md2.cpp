// libFuzzer target: any bytes → a .md2 file → animorder::load_md2.
#include "loader_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = animorder_fuzz::write_input(data, size, "input.md2");
    animorder_fuzz::run_loader(
        [](const std::string& p, const animorder::LoadOptions& o) { return animorder::load_md2(p, o); }, path);
    return 0;
}
