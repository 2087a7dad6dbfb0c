// The loop forms (loop_forms.h): constants in the renderer, switches in its test build.
#include "loop_forms.h"

#include "simd.h"

namespace pt::forms {

#ifdef PT_LOOP_FORMS
Switches& switches() {
  static Switches s;
  return s;
}
bool packets() { return switches().packets; }
bool lanes() { return switches().lanes; }
bool use_avx2() { return switches().avx2 && simd::avx2_available(); }
int packet_width() { return switches().packet_width; }
#else
bool packets() { return true; }
bool lanes() { return true; }
bool use_avx2() { return simd::avx2_available(); }
int packet_width() { return 0; }
#endif

}  // namespace pt::forms
