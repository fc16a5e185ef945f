#include "backends/scalar/run.hpp"

namespace flatmarch::scalar {

template Frame render_in<float>(const Scene&, const Camera&, int, int, const MarchParams&,
                                const Progress&);
template Trace trace_in<float>(const Scene&, const Ray&, const MarchParams&, int);

}  // namespace flatmarch::scalar
