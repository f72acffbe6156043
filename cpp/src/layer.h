/* A layer of a stack as a nested plate defines it: `thinbirefringent` implements LayerSource,
 * and `birefringentstack` reads its layers through it (cross-cast from the nested BSDF).
 */
#pragma once

#include "plugins.h"
#include "differentiable.h"

#include <string>
#include <vector>

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// What one plate contributes to a stack: its material, optic axis and textures (the plate's
/// own parameters, read where they are kept: an update through mi.traverse is seen at once).
template <typename Float, typename Spectrum> struct PlateLayer {
    using TextureT = Texture<Float, Spectrum>;
    using ScalarVector3f = Vector<dr::scalar_t<Float>, 3>;

    const MaterialParams *material = nullptr;
    ScalarVector3f optic_axis;
    /// The plate's differentiable parameters (their Dr.Jit handles in the JIT variants).
    const Differentiable<Float> *diff = nullptr;
    const TextureT *thickness = nullptr;  ///< micrometres, times thickness_scale
    double thickness_scale = 1.0;
    const TextureT *birefringence = nullptr;  ///< none if null
    double birefringence_scale = 1.0;
    const TextureT *axis_angle = nullptr;  ///< degrees; none if null
    /// The parameters given to the plate that describe its surroundings rather than its layer
    /// (`ext_ior`, `exit_ior`, `filter_bandwidth`, `channel`, `absorbing_exit`): a stack refuses
    /// them (they are the stack's).
    const std::vector<std::string> *surroundings = nullptr;
};

/// A BSDF that can be a layer of a stack.
template <typename Float, typename Spectrum> class LayerSource {
public:
    virtual ~LayerSource() = default;
    /// The layer (valid while the BSDF lives and is not rebuilt).
    virtual PlateLayer<Float, Spectrum> layer() const = 0;
    /// Marks the BSDF as a stack's layer: it then exposes to `mi.traverse` only the parameters
    /// of its layer (not `ext_ior`, `exit_ior`, `filter_bandwidth`, which are the stack's).
    virtual void nest() = 0;
};

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
