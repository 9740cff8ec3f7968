// TESAC (task-encoder SAC): no contrastive loss. Its distinctive part is an absence: the context
// encoder learns only through the critic's gradient (ContextSac::update), so there is no sampler
// here; method_contrast("TESAC") is Contrast::kNone and ContextSac skips the SaNCE step.
#include "learn/meta/samplers.h"
