/* The last valid state of a plugin: a rejected parameter update (`mi.traverse`, then
 * `update()` raises) leaves the plugin as it was before the update.
 */
#pragma once

#include "plugins.h"

#include <drjit/tensor.h>

#include <functional>
#include <memory>
#include <typeinfo>
#include <vector>

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/** The values an object exposes to `mi.traverse`, its own and its textures' (recursively),
 * saved so that they can be put back: the last valid state of a plugin, restored when an
 * update is rejected. Values of other types than those listed in `put_value` (none of the
 * plugins' or of Mitsuba's uniform, checkerboard and bitmap textures) are not saved. In the JIT
 * variants a saved Float or Vector3f (a differentiable handle, a uniform texture's value) keeps
 * its AD variable. */
template <typename Float, typename Spectrum> class Snapshot final : public TraversalCallback {
public:
    MI_IMPORT_CORE_TYPES()

    explicit Snapshot(Object *root) { root->traverse(this); }

    /// Writes the saved values back, then lets each saved texture rebuild itself (deepest
    /// first). The root object itself is left to the caller.
    void restore() {
        for (const auto &r : m_restore)
            r();
        for (auto it = m_children.rbegin(); it != m_children.rend(); ++it)
            (*it)->parameters_changed();
    }

protected:
    void put_value(std::string_view, void *value, uint32_t, const std::type_info &type) override {
        if constexpr (dr::is_jit_v<Float>) {
            // The differentiable handles of the JIT variants (differentiable.h).
            if (save<Float>(value, type) || save<Vector3f>(value, type))
                return;
        }
        (void) (save<double>(value, type) || save<float>(value, type) ||
                save<bool>(value, type) || save<int32_t>(value, type) ||
                save<uint32_t>(value, type) || save<ScalarVector3f>(value, type) ||
                save<ScalarPoint3f>(value, type) || save<ScalarColor3f>(value, type) ||
                save<ScalarAffineTransform3f>(value, type) || save<TensorXf>(value, type));
    }

    void put_object(std::string_view, Object *object, uint32_t) override {
        if (!object)
            return;
        m_children.push_back(object);
        object->traverse(this);
    }

private:
    template <typename T> bool save(void *value, const std::type_info &type) {
        if (type != typeid(T))
            return false;
        T *p = static_cast<T *>(value);
        m_restore.push_back([p, saved = *p] { *p = saved; });
        return true;
    }

    std::vector<std::function<void()>> m_restore;
    std::vector<ref<Object>> m_children;
};

/** `parameters_changed` of a plugin: `rebuild` validates every parameter and derives the
 * internal state, throwing on invalid input. On success the traversed values become the last
 * valid state; on failure that state is put back and rebuilt before the error propagates, so a
 * rejected update (`mi.traverse(...)` values set, then `update()` raises) changes nothing: the
 * plugin renders and traverses as before it. */
template <typename Float, typename Spectrum, typename Rebuild>
void update_or_restore(Object *self, std::unique_ptr<Snapshot<Float, Spectrum>> &valid,
                       Rebuild &&rebuild) {
    try {
        rebuild();
    } catch (...) {
        if (valid) {
            valid->restore();
            rebuild();
        }
        throw;
    }
    valid = std::make_unique<Snapshot<Float, Spectrum>>(self);
}

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
