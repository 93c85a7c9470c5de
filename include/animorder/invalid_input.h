// animorder — the one error every algorithm throws for input it cannot accept.
#pragma once

#include <stdexcept>
#include <string>

namespace animorder {

// Thrown for input the algorithms cannot accept; what() says which argument and why.
class InvalidInput : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace animorder
