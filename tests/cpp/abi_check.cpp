// Drives the bridge through its generated C++ header (birefringent/src/ffi/mod.rs.h), as the
// Mitsuba shim does; prints one line per check for tests/cxx_abi.rs, numbers with %.17g (exact
// round trip of a double).
#include "rust/cxx.h"
#include "birefringent/src/ffi/mod.rs.h"

#include <cmath>
#include <cstdio>
#include <vector>

using rust::Slice;

namespace {

// Owned output columns of `n` lanes and `channels` channels.
struct Out {
    size_t n, channels;
    std::vector<bfr::Status> status;
    std::vector<uint32_t> component;
    std::vector<double> pdf, eta, wo[3], in_x[3], out_x[3], value[16];

    Out(size_t n, size_t channels) : n(n), channels(channels), status(n), component(n), pdf(n), eta(n) {
        for (int k = 0; k < 3; ++k) {
            wo[k].resize(n);
            in_x[k].resize(n * channels);
            out_x[k].resize(n * channels);
        }
        for (auto &v : value)
            v.resize(n * channels);
    }

    bfr::Samples samples() {
        bfr::Samples s{};
        s.status = { status.data(), n };
        s.component = { component.data(), n };
        s.pdf = { pdf.data(), n };
        s.eta = { eta.data(), n };
        for (int k = 0; k < 3; ++k) {
            s.wo[k] = { wo[k].data(), n };
            s.in_stokes_x[k] = { in_x[k].data(), n * channels };
            s.out_stokes_x[k] = { out_x[k].data(), n * channels };
        }
        for (int k = 0; k < 16; ++k)
            s.value[k] = { value[k].data(), n * channels };
        return s;
    }

    void print(const char *tag, bfr::Status rc, const rust::String &message) const {
        std::printf("%s %d [%s]\n", tag, (int) rc, std::string(message).c_str());
        for (size_t i = 0; i < n; ++i) {
            std::printf("lane %d %u %.17g %.17g %.17g %.17g %.17g", (int) status[i], component[i],
                        pdf[i], eta[i], wo[0][i], wo[1][i], wo[2][i]);
            for (size_t c = 0; c < channels; ++c) {
                size_t at = c * n + i;
                for (int k = 0; k < 3; ++k)
                    std::printf(" %.17g %.17g", in_x[k][at], out_x[k][at]);
                for (int k = 0; k < 16; ++k)
                    std::printf(" %.17g", value[k][at]);
            }
            std::printf("\n");
        }
    }
};

}  // namespace

int main() {
    std::printf("version %s\n", std::string(bfr::version()).c_str());
    std::printf("bounds %d %d %d\n", (int) bfr::Bounds::MaxChannels, (int) bfr::Bounds::PlateComponents,
                (int) bfr::Bounds::CrystalComponents);

    rust::Box<bfr::Materials> m = bfr::new_materials();
    uint32_t calcite = m->add_named("calcite", 0.0, 0.0);
    uint32_t glass = m->add_constant(1.5, 1.5, 0.0, 0.0);
    std::printf("materials %u %u %d %d\n", calcite, glass, (int) m->is_isotropic(calcite),
                (int) m->is_isotropic(glass));
    try {
        m->add_named("unobtainium", 0.0, 0.0);
        std::printf("bad material accepted\n");
    } catch (const rust::Error &e) {
        std::printf("bad material [%s]\n", e.what());
    }

    // Three lanes: outside, inside and outside at another azimuth, mixed materials and modes;
    // columns of one value are broadcast.
    const size_t n = 3;
    const uint8_t active[] = { 1, 1, 1 };
    const uint32_t material[] = { calcite, glass, calcite };
    const bfr::Transport transport[] = { bfr::Transport::Radiance, bfr::Transport::Importance,
                                         bfr::Transport::Importance };
    const double sample[] = { 0.1, 0.5, 0.9 };
    const double wx[] = { 0.3, -0.2, 0.0 }, wy[] = { 0.2, 0.1, 0.6 };
    const double wz[] = { std::sqrt(1 - 0.13), -std::sqrt(1 - 0.05), std::sqrt(1 - 0.36) };
    const double l0[] = { 450.0, 500.0, 650.0 }, l1[] = { 550.0 }, l2[] = { 600.0, 610.0, 620.0 };
    const Slice<const double> waves[] = { { l0, n }, { l1, 1 }, { l2, n } };
    const double one[] = { 1.0 }, exit_ior[] = { 1.33 }, ax[] = { 0.7021 }, ay[] = { 0.0 },
                 az[] = { 0.7120 }, thickness[] = { 2500.0 }, zero[] = { 0.0 };

    bfr::PlateLanes p{};
    p.count = n;
    p.active = { active, n };
    p.material = { material, n };
    p.transport = { transport, n };
    p.sample = { sample, n };
    p.wi = { Slice<const double>(wx, n), Slice<const double>(wy, n), Slice<const double>(wz, n) };
    p.wavelengths_nm = { waves, 3 };
    p.ext_ior = { one, 1 };
    p.exit_ior = { exit_ior, 1 };
    p.optic_axis = { Slice<const double>(ax, 1), Slice<const double>(ay, 1), Slice<const double>(az, 1) };
    p.axis_angle_deg = { zero, 1 };
    p.thickness_nm = { thickness, 1 };
    p.birefringence = { zero, 1 };

    rust::Box<bfr::PlateSpectrum> band = bfr::band_spectrum(4.0);
    bfr::PlateCall call{ 3u, false, false };
    {
        Out out(n, band->channels(3));
        bfr::Samples s = out.samples();
        bfr::Status rc = bfr::sample_plate(*m, *band, call, p, s);
        out.print("plate", rc, s.message);
    }
    {
        // A band wider than a quarter of a wavelength fails in every lane.
        rust::Box<bfr::PlateSpectrum> wide = bfr::band_spectrum(200.0);
        Out out(n, 3);
        bfr::Samples s = out.samples();
        bfr::Status rc = bfr::sample_plate(*m, *wide, call, p, s);
        std::printf("wide band %d %d [%s]\n", (int) rc, (int) out.status[0], std::string(s.message).c_str());
    }
    {
        rust::Box<bfr::PlateSpectrum> srgb = bfr::srgb_spectrum();
        bfr::PlateLanes rgb = p;
        rgb.wavelengths_nm = {};
        Out out(n, srgb->channels(0));
        bfr::Samples s = out.samples();
        bfr::Status rc = bfr::sample_plate(*m, *srgb, call, rgb, s);
        out.print("rgb", rc, s.message);
    }
    bfr::CrystalLanes c{};
    c.count = n;
    c.active = p.active;
    c.material = p.material;
    c.transport = p.transport;
    c.sample = p.sample;
    c.wi = p.wi;
    c.wavelengths_nm = p.wavelengths_nm;
    c.ext_ior = p.ext_ior;
    c.optic_axis = p.optic_axis;
    {
        Out out(n, 3);
        bfr::Samples s = out.samples();
        bfr::Status rc = bfr::sample_crystal(*m, 7u, c, s);
        out.print("crystal", rc, s.message);
    }
    {
        // A zero optic axis fails in every lane; the first lane's message is returned.
        const double z3[] = { 0.0 };
        bfr::CrystalLanes bad = c;
        bad.optic_axis = { Slice<const double>(z3, 1), Slice<const double>(z3, 1), Slice<const double>(z3, 1) };
        Out out(n, 3);
        bfr::Samples s = out.samples();
        bfr::Status rc = bfr::sample_crystal(*m, 7u, bad, s);
        std::printf("bad axis %d %d [%s]\n", (int) rc, (int) out.status[0], std::string(s.message).c_str());
    }
    {
        // A column of the wrong length refuses the call.
        bfr::CrystalLanes bad = c;
        bad.sample = { sample, 2 };
        Out out(n, 3);
        bfr::Samples s = out.samples();
        bfr::Status rc = bfr::sample_crystal(*m, 7u, bad, s);
        std::printf("short column %d [%s]\n", (int) rc, std::string(s.message).c_str());
    }
    return 0;
}
