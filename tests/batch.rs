//! The batch entry points of the bridge (`ffi::sample_plate`, `ffi::sample_crystal`): every lane
//! of a batch equals the scalar query of the core, bit for bit (the same f64 operations in the
//! same order: `PlateQuery` + `plate_lobes`, or `crystal_slots` per wavelength, then the choice
//! of a lobe, here written out from its documentation rather than by calling `choose`), over
//! random batches that mix materials, sides, transport modes, directions, wavelengths, geometry,
//! failing lanes and every channel of every weight set; one-lane batches (what the scalar
//! variants send) equal the big batch; the choice is an unbiased sampler of every channel; a
//! single-value column equals the same value repeated (broadcast); columns of the wrong length
//! are refused with a message naming them.

use birefringent::colour::weights::WeightSet;
use birefringent::ffi::bridge::{
    CrystalLanes, PlateCall, PlateLanes, Samples, Status, Transport as T,
};
use birefringent::ffi::{
    band_spectrum, colour_channel_spectrum, exact_spectrum, new_materials, sample_crystal,
    sample_plate, srgb_spectrum, Materials, PlateSpectrum,
};
use birefringent::material::Material;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::params::{Length, Thickness};
use birefringent::render::choice::Choice;
use birefringent::render::crystal::crystal_slots;
use birefringent::render::plate::{plate_lobes, PlateQuery};
use birefringent::render::slots::{crystal_component, Slots, CRYSTAL_SLOTS};
use birefringent::render::thin::Spectrum;
use birefringent::render::{PathLobe, Transport};
use birefringent::C64;
use nalgebra::Vector3;

mod common;
use common::Rng;

/// Owned input columns of a batch (both queries' columns; the crystal ignores the plate's).
#[derive(Clone, Default)]
struct Lanes {
    count: usize,
    active: Vec<u8>,
    material: Vec<u32>,
    transport: Vec<T>,
    sample: Vec<f64>,
    wi: [Vec<f64>; 3],
    wavelengths: Vec<Vec<f64>>,
    ext_ior: Vec<f64>,
    exit_ior: Vec<f64>,
    optic_axis: [Vec<f64>; 3],
    axis_angle_deg: Vec<f64>,
    thickness_nm: Vec<f64>,
    birefringence: Vec<f64>,
}

impl Lanes {
    fn plate(&self) -> (PlateLanes<'_>, Vec<&[f64]>) {
        let waves: Vec<&[f64]> = self.wavelengths.iter().map(|w| w.as_slice()).collect();
        let lanes = PlateLanes {
            count: self.count,
            active: &self.active,
            material: &self.material,
            transport: &self.transport,
            sample: &self.sample,
            wi: [&self.wi[0], &self.wi[1], &self.wi[2]],
            wavelengths_nm: &[],
            ext_ior: &self.ext_ior,
            exit_ior: &self.exit_ior,
            optic_axis: [
                &self.optic_axis[0],
                &self.optic_axis[1],
                &self.optic_axis[2],
            ],
            axis_angle_deg: &self.axis_angle_deg,
            thickness_nm: &self.thickness_nm,
            birefringence: &self.birefringence,
        };
        (lanes, waves)
    }

    fn crystal<'a>(&'a self, waves: &'a [&'a [f64]]) -> CrystalLanes<'a> {
        CrystalLanes {
            count: self.count,
            active: &self.active,
            material: &self.material,
            transport: &self.transport,
            sample: &self.sample,
            wi: [&self.wi[0], &self.wi[1], &self.wi[2]],
            wavelengths_nm: waves,
            ext_ior: &self.ext_ior,
            optic_axis: [
                &self.optic_axis[0],
                &self.optic_axis[1],
                &self.optic_axis[2],
            ],
        }
    }

    /// Lane `i` alone (every column of length 1).
    fn lane(&self, i: usize) -> Lanes {
        let one = |v: &Vec<f64>| vec![v[if v.len() == 1 { 0 } else { i }]];
        Lanes {
            count: 1,
            active: vec![self.active[i]],
            material: vec![self.material[i]],
            transport: vec![self.transport[i]],
            sample: vec![self.sample[i]],
            wi: self.wi.clone().map(|v| one(&v)),
            wavelengths: self.wavelengths.iter().map(one).collect(),
            ext_ior: one(&self.ext_ior),
            exit_ior: one(&self.exit_ior),
            optic_axis: self.optic_axis.clone().map(|v| one(&v)),
            axis_angle_deg: one(&self.axis_angle_deg),
            thickness_nm: one(&self.thickness_nm),
            birefringence: one(&self.birefringence),
        }
    }
}

/// Owned output columns.
#[derive(Clone, Debug, PartialEq)]
struct Out {
    status: Vec<Status>,
    component: Vec<u32>,
    pdf: Vec<f64>,
    eta: Vec<f64>,
    wo: [Vec<f64>; 3],
    in_x: [Vec<f64>; 3],
    out_x: [Vec<f64>; 3],
    value: Vec<Vec<f64>>,
    message: String,
}

impl Out {
    /// Columns for `n` lanes of `channels` channels; `full`: frames and 16 entries.
    fn new(n: usize, channels: usize, full: bool) -> Self {
        let per = |on: bool| vec![f64::NAN; if on { n * channels } else { 0 }];
        Out {
            status: vec![Status::Internal; n],
            component: vec![99; n],
            pdf: vec![f64::NAN; n],
            eta: vec![f64::NAN; n],
            wo: std::array::from_fn(|_| vec![f64::NAN; n]),
            in_x: std::array::from_fn(|_| per(full)),
            out_x: std::array::from_fn(|_| per(full)),
            value: (0..16).map(|k| per(k == 0 || full)).collect(),
            message: String::new(),
        }
    }

    fn samples(&mut self) -> Samples<'_> {
        let [a, b, c] = &mut self.wo;
        let [d, e, f] = &mut self.in_x;
        let [g, h, k] = &mut self.out_x;
        let mut values = self.value.iter_mut();
        Samples {
            status: &mut self.status,
            component: &mut self.component,
            pdf: &mut self.pdf,
            eta: &mut self.eta,
            wo: [a, b, c],
            in_stokes_x: [d, e, f],
            out_stokes_x: [g, h, k],
            value: std::array::from_fn(|_| values.next().unwrap().as_mut_slice()),
            message: String::new(),
        }
    }

    fn run_plate(
        &mut self,
        m: &Materials,
        s: &PlateSpectrum,
        call: &PlateCall,
        l: &Lanes,
    ) -> Status {
        let (mut lanes, waves) = l.plate();
        lanes.wavelengths_nm = &waves;
        let mut samples = self.samples();
        let rc = sample_plate(m, s, call, &lanes, &mut samples);
        let message = std::mem::take(&mut samples.message);
        self.message = message;
        rc
    }

    fn run_crystal(&mut self, m: &Materials, components: u32, l: &Lanes) -> Status {
        let waves: Vec<&[f64]> = l.wavelengths.iter().map(|w| w.as_slice()).collect();
        let lanes = l.crystal(&waves);
        let mut samples = self.samples();
        let rc = sample_crystal(m, components, &lanes, &mut samples);
        let message = std::mem::take(&mut samples.message);
        self.message = message;
        rc
    }

    /// Lane `i`'s numbers as bits (status, component, then every f64 of its columns).
    fn lane_bits(&self, i: usize, channels: usize) -> Vec<u64> {
        let n = self.status.len();
        let mut v = vec![self.status[i].repr as u64, self.component[i] as u64];
        v.extend([self.pdf[i], self.eta[i]].map(f64::to_bits));
        v.extend(self.wo.iter().map(|c| c[i].to_bits()));
        for ch in 0..channels {
            for c in self.in_x.iter().chain(&self.out_x).chain(&self.value) {
                if !c.is_empty() {
                    v.push(c[ch * n + i].to_bits());
                }
            }
        }
        v
    }
}

/// The materials of the mixed batches: named crystals, a constant birefringent medium, an
/// isotropic glass, a dichroic plate material and an absorbing isotropic medium (a metal).
fn materials() -> (Box<Materials>, Vec<Material>) {
    let mut m = new_materials();
    let mut core = Vec::new();
    for (name, ko, ke) in [
        ("calcite", 0.0, 0.0),
        ("quartz", 0.0, 0.0),
        ("rutile", 0.0, 0.0),
    ] {
        m.add_named(name, ko, ke).unwrap();
        core.push(Material::named(name, ko, ke).unwrap());
    }
    for (o, e, ko, ke) in [
        (1.5, 1.62, 0.0, 0.0),
        (1.5, 1.5, 0.0, 0.0),
        (1.55, 1.58, 0.0, 0.02),
        (0.5, 0.5, 2.5, 2.5),
    ] {
        m.add_constant(o, e, ko, ke).unwrap();
        core.push(Material::constant(C64::new(o, ko), C64::new(e, ke)).unwrap());
    }
    (m, core)
}

/// `n` random lanes with `waves` wavelength columns; about 2 % have an invalid thickness
/// (negative) and 5 % are inactive.
fn random_lanes(rng: &mut Rng, n: usize, waves: usize, materials: usize) -> Lanes {
    let mut l = Lanes {
        count: n,
        wavelengths: vec![Vec::new(); waves],
        ..Default::default()
    };
    for _ in 0..n {
        l.active.push(u8::from(!rng.chance(0.05)));
        l.material.push(rng.index(materials) as u32);
        l.transport.push(if rng.chance(0.5) {
            T::Radiance
        } else {
            T::Importance
        });
        l.sample.push(rng.uniform());
        let wi = loop {
            let v = rng.unit_vector();
            if v.z.abs() > 1e-3 {
                break v;
            }
        };
        for k in 0..3 {
            l.wi[k].push(wi[k]);
        }
        for w in l.wavelengths.iter_mut() {
            w.push(rng.range(420.0, 700.0));
        }
        l.ext_ior.push(if rng.chance(0.5) {
            1.0
        } else {
            rng.range(1.0, 1.6)
        });
        l.exit_ior.push(if rng.chance(0.5) {
            1.0
        } else {
            rng.range(1.0, 1.6)
        });
        let a = rng.unit_vector();
        for k in 0..3 {
            l.optic_axis[k].push(a[k]);
        }
        let angle = if rng.chance(0.5) {
            0.0
        } else {
            rng.range(-180.0, 180.0)
        };
        l.axis_angle_deg.push(angle);
        let t = 10f64.powf(rng.range(1.0, 4.5));
        l.thickness_nm.push(if rng.chance(0.02) { -t } else { t });
        l.birefringence.push(if rng.chance(0.3) {
            rng.range(-0.01, 0.01)
        } else {
            0.0
        });
    }
    l
}

fn transport(t: T) -> Transport {
    if t == T::Radiance {
        Transport::Radiance
    } else {
        Transport::Importance
    }
}

fn enabled(components: u32, k: usize) -> bool {
    components & (1 << k) != 0
}

/// What lane `i` must hold, by the scalar core API: `Err` for an invalid lane, `None` for a
/// lane that samples nothing, else the channels' lobes and the choice.
type Expected<const S: usize> = Result<Option<(Vec<Slots<S>>, Choice)>, String>;

fn plate_expected(
    core: &[Material],
    l: &Lanes,
    spectrum: Spectrum,
    pick: Option<usize>,
    call: &PlateCall,
    i: usize,
) -> Expected<2> {
    let at = |v: &Vec<f64>| v[if v.len() == 1 { 0 } else { i }];
    // The axis rotated about the normal by axis_angle (counter-clockwise seen from +z).
    let a = Vector3::new(
        at(&l.optic_axis[0]),
        at(&l.optic_axis[1]),
        at(&l.optic_axis[2]),
    );
    let degrees = at(&l.axis_angle_deg);
    let (s, c) = degrees.to_radians().sin_cos();
    let axis = if degrees == 0.0 {
        a
    } else {
        Vector3::new(c * a.x - s * a.y, s * a.x + c * a.y, a.z)
    };
    let thickness = Thickness::new("thickness", at(&l.thickness_nm), Length::Micrometres)
        .map_err(|e| e.to_string())?;
    let q = PlateQuery::new(
        core[l.material[i] as usize],
        at(&l.birefringence),
        C64::new(at(&l.ext_ior), 0.0),
        C64::new(at(&l.exit_ior), 0.0),
        axis,
        thickness,
        enabled(call.components, 0),
        enabled(call.components, 1),
        call.intensity_only,
    )
    .map_err(|e| e.to_string())?
    .with_absorbing_exit(call.absorbing_exit);
    let spectrum = match spectrum {
        Spectrum::Bands { fwhm_nm, .. } => {
            let mut w = [0.0; 4];
            for (k, c) in l.wavelengths.iter().enumerate() {
                w[k] = at(c);
            }
            Spectrum::Bands {
                wavelengths_nm: w,
                count: l.wavelengths.len(),
                fwhm_nm,
            }
        }
        s => s,
    };
    let wi = Vector3::new(at(&l.wi[0]), at(&l.wi[1]), at(&l.wi[2]));
    let mut lobes =
        plate_lobes(&q, &spectrum, wi, transport(l.transport[i])).map_err(|e| e.to_string())?;
    // A one-channel query (a channel render's pass) chooses over the whole set, so that every
    // pass of a render chooses alike, and keeps its own channel.
    let choice = expected_choice(&lobes, |s| enabled(call.components, s), l.sample[i]);
    if let Some(k) = pick {
        lobes = vec![lobes[k]];
    }
    Ok(choice.map(|c| {
        let hero = if pick.is_some() { 0 } else { c.hero };
        (lobes, Choice { hero, ..c })
    }))
}

fn crystal_expected(
    core: &[Material],
    l: &Lanes,
    components: u32,
    i: usize,
) -> Expected<CRYSTAL_SLOTS> {
    let at = |v: &Vec<f64>| v[if v.len() == 1 { 0 } else { i }];
    let axis = Vector3::new(
        at(&l.optic_axis[0]),
        at(&l.optic_axis[1]),
        at(&l.optic_axis[2]),
    );
    let wi = Vector3::new(at(&l.wi[0]), at(&l.wi[1]), at(&l.wi[2]));
    let mut lobes = Vec::new();
    for w in &l.wavelengths {
        let (eo, ee) = core[l.material[i] as usize]
            .indices(at(w), 0.0)
            .map_err(|e| e.to_string())?;
        let s = Surface::new(
            C64::new(at(&l.ext_ior), 0.0),
            Uniaxial::new(eo, ee, axis).map_err(|e| e.to_string())?,
        )
        .map_err(|e| e.to_string())?;
        lobes.push(crystal_slots(&s, wi, transport(l.transport[i])).map_err(|e| e.to_string())?);
    }
    Ok(expected_choice(
        &lobes,
        |s| enabled(components, crystal_component(s)),
        l.sample[i],
    )
    .map(|c| (lobes, c)))
}

/// The choice documented in src/render/choice.rs, written here apart from `choose` (which the
/// batch calls): the candidates are the enabled slots that some channel has, each weighted by
/// its power fraction's |M00| (`PathLobe::power`: without Radiance mode's radiance factor)
/// summed over the channels; a lone candidate is taken with probability 1; else `u`
/// walks the cumulative weights of the slots of positive weight in slot order (the first whose
/// running sum exceeds `u * total`, the last one if rounding leaves none), with probability
/// weight / total; the ray follows the slot in the first channel that has it (the hero). The
/// same sums in the same order, so the same bits.
fn expected_choice<const S: usize>(
    lobes: &[Slots<S>],
    enabled: impl Fn(usize) -> bool,
    u: f64,
) -> Option<Choice> {
    let candidates: Vec<(usize, f64)> = (0..S)
        .filter(|&s| enabled(s) && lobes.iter().any(|c| c[s].is_some()))
        .map(|s| {
            (
                s,
                lobes
                    .iter()
                    .filter_map(|c| c[s])
                    .map(|l| l.power.abs())
                    .sum(),
            )
        })
        .collect();
    let hero = |s: usize| lobes.iter().take_while(|c| c[s].is_none()).count();
    if let [(slot, _)] = candidates[..] {
        return Some(Choice {
            slot,
            pdf: 1.0,
            hero: hero(slot),
        });
    }
    let total: f64 = candidates.iter().map(|&(_, w)| w).sum();
    if candidates.is_empty() || total.is_nan() || total <= 0.0 {
        return None;
    }
    let positive: Vec<(usize, f64)> = candidates.into_iter().filter(|&(_, w)| w > 0.0).collect();
    let mut running = 0.0;
    let &(slot, w) = positive
        .iter()
        .find(|&&(_, w)| {
            running += w;
            u * total < running
        })
        .unwrap_or_else(|| positive.last().unwrap());
    Some(Choice {
        slot,
        pdf: w / total,
        hero: hero(slot),
    })
}

/// The bits lane `i` must have (same layout as `Out::lane_bits`).
fn expected_bits<const S: usize>(
    e: &Expected<S>,
    channels: usize,
    full: bool,
    component: fn(usize) -> usize,
) -> Vec<u64> {
    let entries = if full { 22 } else { 1 };
    let zero = |status: Status| {
        let mut v = vec![status.repr as u64, 0, 0, 0, 0, 0, 0];
        v.extend(std::iter::repeat_n(0, entries * channels));
        v
    };
    let (lobes, c) = match e {
        Err(_) => return zero(Status::Invalid),
        Ok(None) => return zero(Status::Ok),
        Ok(Some(x)) => x,
    };
    let hero: PathLobe = lobes[c.hero][c.slot].unwrap();
    let mut v = vec![Status::Ok.repr as u64, component(c.slot) as u64];
    v.extend([c.pdf, hero.eta].map(f64::to_bits));
    v.extend(hero.wo.iter().map(|x| x.to_bits()));
    for slots in lobes.iter().take(channels) {
        let l = slots[c.slot];
        if full {
            let f = l.unwrap_or(hero);
            v.extend(
                f.in_stokes_x
                    .iter()
                    .chain(f.out_stokes_x.iter())
                    .map(|x| x.to_bits()),
            );
        }
        for k in 0..if full { 16 } else { 1 } {
            let m = l.map_or(0.0, |l| l.mueller[(k / 4, k % 4)] / c.pdf);
            v.push(m.to_bits());
        }
    }
    v
}

fn plate_spectra() -> Vec<(Box<PlateSpectrum>, Spectrum, Option<usize>, usize)> {
    let bands = |fwhm_nm| Spectrum::Bands {
        wavelengths_nm: [0.0; 4],
        count: 0,
        fwhm_nm,
    };
    vec![
        (exact_spectrum(), bands(0.0), None, 4),
        (band_spectrum(4.0), bands(4.0), None, 3),
        (
            srgb_spectrum(),
            Spectrum::Weights(WeightSet::SrgbD65),
            None,
            0,
        ),
    ]
    .into_iter()
    .chain(every_channel())
    .collect()
}

/// Every channel of every weight set, as a one-channel query (a channel render's pass), by
/// name.
fn every_channel() -> Vec<(Box<PlateSpectrum>, Spectrum, Option<usize>, usize)> {
    let sets = [
        ("srgb-d65", WeightSet::SrgbD65, ["R", "G", "B"]),
        ("xyz-d65", WeightSet::XyzD65, ["X", "Y", "Z"]),
        ("xyz-e", WeightSet::XyzE, ["X", "Y", "Z"]),
    ];
    let mut out = Vec::new();
    for (name, set, letters) in sets {
        for (k, letter) in letters.iter().enumerate() {
            let spectrum = colour_channel_spectrum(&format!("{name}:{letter}")).unwrap();
            out.push((spectrum, Spectrum::Weights(set), Some(k), 0));
        }
    }
    out
}

/// Plate batches for every spectrum kind, every component set and both output forms (300 lanes
/// per batch; 20 for the sRGB set and 10 for each channel of each weight set alone, whose
/// closed-form integration costs milliseconds per query): each lane equals the scalar query bit
/// for bit; so does every tenth lane sent alone.
#[test]
fn plate_batches_equal_scalar_queries_bit_for_bit() {
    let (m, core) = materials();
    let mut rng = Rng::new(7);
    let (mut lanes_checked, mut invalid, mut sampled) = (0, 0, 0);
    for (spectrum, core_spectrum, pick, waves) in plate_spectra() {
        for components in [1u32, 2, 3] {
            for (full, absorbing_exit) in [(true, false), (false, false), (true, true)] {
                let n = match (waves, pick) {
                    (0, Some(_)) => 10,
                    (0, None) => 20,
                    _ => 300,
                };
                let l = random_lanes(&mut rng, n, waves, core.len());
                let call = PlateCall {
                    components,
                    intensity_only: !full,
                    absorbing_exit,
                };
                let channels = spectrum.channels(waves);
                let mut out = Out::new(n, channels, full);
                let rc = out.run_plate(&m, &spectrum, &call, &l);
                let mut first_error = None;
                for i in 0..n {
                    let e = if l.active[i] == 0 {
                        Ok(None)
                    } else {
                        plate_expected(&core, &l, core_spectrum, pick, &call, i)
                    };
                    if let Err(msg) = &e {
                        first_error.get_or_insert(msg.clone());
                        invalid += 1;
                    }
                    sampled += usize::from(matches!(e, Ok(Some(_))));
                    let want = expected_bits(&e, channels, full, |s| s);
                    assert_eq!(out.lane_bits(i, channels), want, "lane {i}: {e:?}");
                    if i % 10 == 0 {
                        let mut one = Out::new(1, channels, full);
                        one.run_plate(&m, &spectrum, &call, &l.lane(i));
                        assert_eq!(one.lane_bits(0, channels), want, "lane {i} alone");
                    }
                    lanes_checked += 1;
                }
                match first_error {
                    Some(msg) => {
                        assert_eq!(rc, Status::Invalid);
                        assert_eq!(out.message, msg);
                    }
                    None => assert_eq!(rc, Status::Ok),
                }
            }
        }
    }
    println!("{lanes_checked} plate lanes equal bit for bit ({sampled} sampled a lobe, {invalid} invalid)");
    assert!(invalid > 50 && sampled > lanes_checked / 2);
}

/// The choice is an unbiased sampler of every channel's lobes, checked through the batch path
/// without its rule: each plate lane (exact at four wavelengths, and over the sRGB set, signed)
/// is sent K times with the lobe number on a grid of K stratified values. The fraction of the
/// grid that picks a slot is the probability the batch reports for it (to one grid step), the
/// slots' probabilities sum to 1, and Σ pdf · value over the slots is each channel's sum of its
/// lobes (`plate_lobes` directly), entry by entry, to 1e-12 relative: every channel's
/// expectation holds. Among the lanes: a lithium niobate film on silica whose reflection is
/// negative in sRGB R (out of gamut): its expectation holds with a negative channel too.
#[test]
fn the_choice_is_an_unbiased_sampler_of_every_channel() {
    const K: usize = 1000;
    let (mut m, mut core) = materials();
    m.add_named("linbo3", 0.0, 0.0).unwrap();
    core.push(Material::named("linbo3", 0.0, 0.0).unwrap());
    let linbo3 = core.len() as u32 - 1;
    let grid: Vec<f64> = (0..K).map(|k| (k as f64 + 0.5) / K as f64).collect();
    let call = PlateCall {
        components: 3,
        intensity_only: false,
        absorbing_exit: false,
    };
    let mut rng = Rng::new(12);
    let (mut lanes_checked, mut negative) = (0, 0);
    for (spectrum, core_spectrum, waves, n) in [
        (
            exact_spectrum(),
            Spectrum::Bands {
                wavelengths_nm: [0.0; 4],
                count: 0,
                fwhm_nm: 0.0,
            },
            4,
            30,
        ),
        (srgb_spectrum(), Spectrum::Weights(WeightSet::SrgbD65), 0, 4),
    ] {
        let mut l = random_lanes(&mut rng, n, waves, core.len());
        l.active.fill(1);
        l.thickness_nm.iter_mut().for_each(|t| *t = t.abs());
        if waves == 0 {
            // Thin films away from grazing: a thick plate, or a thin one near grazing (1 um of
            // calcite at |cos| = 0.0065: measured 0.24 s), over a channel set costs up to 0.1 s
            // a query.
            l.thickness_nm.iter_mut().for_each(|t| *t = t.min(1000.0));
            for i in 0..n {
                let z = l.wi[2][i];
                if z.abs() < 0.5 {
                    let s = 0.75f64.sqrt() / l.wi[0][i].hypot(l.wi[1][i]);
                    (l.wi[0][i], l.wi[1][i], l.wi[2][i]) =
                        (s * l.wi[0][i], s * l.wi[1][i], 0.5f64.copysign(z));
                }
            }
            // The film of tests/sampling.rs (srgb_lobes_keep_negative_channels), 285 nm at 40°.
            let theta = 40f64.to_radians();
            (
                l.material[0],
                l.thickness_nm[0],
                l.ext_ior[0],
                l.exit_ior[0],
            ) = (linbo3, 285.0, 1.0, 1.458);
            (l.axis_angle_deg[0], l.birefringence[0]) = (0.0, 0.0);
            for (k, v) in [(0, 1.0), (1, 0.0), (2, 0.0)] {
                l.optic_axis[k][0] = v;
            }
            for (k, v) in [(0, 0.0), (1, -theta.sin()), (2, theta.cos())] {
                l.wi[k][0] = v;
            }
            l.transport[0] = T::Importance;
        }
        let channels = spectrum.channels(waves);
        for i in 0..n {
            let Ok(Some((lobes, _))) = plate_expected(&core, &l, core_spectrum, None, &call, i)
            else {
                continue;
            };
            let mut sweep = l.lane(i);
            sweep.count = K;
            sweep.sample = grid.clone();
            sweep.active = vec![1; K];
            sweep.material = vec![l.material[i]; K];
            sweep.transport = vec![l.transport[i]; K];
            let mut out = Out::new(K, channels, true);
            assert_eq!(out.run_plate(&m, &spectrum, &call, &sweep), Status::Ok);
            // Per slot (the plate's component): how often, its pdf, its value per channel.
            let mut picked: [(usize, f64, Vec<f64>); 2] = Default::default();
            for k in 0..K {
                let slot = out.component[k] as usize;
                let value: Vec<f64> = (0..channels * 16)
                    .map(|e| out.value[e % 16][(e / 16) * K + k])
                    .collect();
                let (count, pdf, v) = &mut picked[slot];
                if *count > 0 {
                    assert_eq!(
                        (*pdf, &*v),
                        (out.pdf[k], &value),
                        "lane {i}: slot {slot} varies"
                    );
                }
                (*count, *pdf, *v) = (*count + 1, out.pdf[k], value);
            }
            // A slot the grid never picks must be one of probability below a grid step: one
            // whose power fraction (|M00|), summed over the channels, is below 1/K of the
            // lobes' total.
            let weight = |slot: usize| -> f64 {
                let w = lobes.iter().take(channels).filter_map(|c| c[slot]);
                w.map(|l| l.power.abs()).sum()
            };
            let all = weight(0) + weight(1);
            let total: f64 = picked.iter().filter(|p| p.0 > 0).map(|p| p.1).sum();
            let missed = picked.iter().any(|p| p.0 == 0);
            assert!(
                (total - 1.0).abs() < 1e-12 || missed && total > 1.0 - 1.0 / K as f64,
                "lane {i}: probabilities sum to {total}"
            );
            for (slot, (count, pdf, value)) in picked.iter().enumerate() {
                if *count == 0 {
                    let w = weight(slot);
                    assert!(
                        w <= all / K as f64,
                        "lane {i}: slot {slot} of weight {w} of {all} never chosen"
                    );
                    continue;
                }
                let expected = pdf * K as f64;
                assert!(
                    (*count as f64 - expected).abs() <= 1.0 + 1e-9,
                    "lane {i} slot {slot}: {count} of {K}, pdf {pdf}"
                );
                for (ch, slots) in lobes.iter().take(channels).enumerate() {
                    let lobe = slots[slot].expect("a chosen slot is in every channel of a plate");
                    negative += usize::from(lobe.weight < 0.0);
                    for e in 0..16 {
                        let want = lobe.mueller[(e / 4, e % 4)];
                        let got = pdf * value[ch * 16 + e];
                        assert!(
                            (got - want).abs() <= 1e-12 * want.abs().max(lobe.weight.abs()),
                            "lane {i} slot {slot} channel {ch} entry {e}: {got} vs {want}"
                        );
                    }
                }
            }
            lanes_checked += 1;
        }
    }
    println!("{lanes_checked} plate lanes swept over {K} lobe numbers ({negative} negative lobes)");
    assert!(lanes_checked > 30 && negative > 0);
}

/// Crystal batches (1 to 4 wavelengths, every component set): each lane equals the scalar
/// query bit for bit, alone too. The absorbing birefringent material (index 5) is refused per
/// lane (its bulk rays are undefined).
#[test]
fn crystal_batches_equal_scalar_queries_bit_for_bit() {
    let (m, core) = materials();
    let mut rng = Rng::new(8);
    let (mut lanes_checked, mut invalid, mut sampled) = (0, 0, 0);
    for waves in 1..=4 {
        for components in [1u32, 2, 4, 6, 7] {
            let n = 400;
            let l = random_lanes(&mut rng, n, waves, core.len());
            let mut out = Out::new(n, waves, true);
            out.run_crystal(&m, components, &l);
            for i in 0..n {
                let e = if l.active[i] == 0 {
                    Ok(None)
                } else {
                    crystal_expected(&core, &l, components, i)
                };
                invalid += usize::from(e.is_err());
                sampled += usize::from(matches!(e, Ok(Some(_))));
                let want = expected_bits(&e, waves, true, crystal_component);
                assert_eq!(out.lane_bits(i, waves), want, "lane {i}: {e:?}");
                if i % 10 == 0 {
                    let mut one = Out::new(1, waves, true);
                    one.run_crystal(&m, components, &l.lane(i));
                    assert_eq!(one.lane_bits(0, waves), want, "lane {i} alone");
                }
                lanes_checked += 1;
            }
        }
    }
    println!("{lanes_checked} crystal lanes equal bit for bit ({sampled} sampled a lobe, {invalid} invalid)");
    assert!(invalid > 100 && sampled > lanes_checked / 2);
}

/// A column of one value is that value for every lane; columns of another length, too many
/// wavelength columns, output columns of the wrong length, a material index outside the table,
/// an unknown transport value, a sample outside [0, 1], a non-finite axis angle, a negative
/// thickness and a band wider than a quarter of its wavelength are refused with a message
/// naming them.
#[test]
fn broadcast_columns_and_refusals() {
    let (m, core) = materials();
    let mut rng = Rng::new(9);
    let n = 50;
    let mut l = random_lanes(&mut rng, n, 4, core.len());
    for v in [
        &mut l.ext_ior,
        &mut l.exit_ior,
        &mut l.thickness_nm,
        &mut l.birefringence,
        &mut l.axis_angle_deg,
    ] {
        *v = vec![v[0].abs()];
    }
    for v in l.optic_axis.iter_mut().chain(l.wavelengths.iter_mut()) {
        *v = vec![v[0]];
    }
    let mut repeated = l.clone();
    for v in [
        &mut repeated.ext_ior,
        &mut repeated.exit_ior,
        &mut repeated.thickness_nm,
        &mut repeated.birefringence,
        &mut repeated.axis_angle_deg,
    ]
    .into_iter()
    .chain(repeated.optic_axis.iter_mut())
    .chain(repeated.wavelengths.iter_mut())
    {
        *v = vec![v[0]; n];
    }
    let spectrum = band_spectrum(4.0);
    let call = PlateCall {
        components: 3,
        intensity_only: false,
        absorbing_exit: false,
    };
    let (mut a, mut b) = (Out::new(n, 4, true), Out::new(n, 4, true));
    assert_eq!(a.run_plate(&m, &spectrum, &call, &l), Status::Ok);
    assert_eq!(b.run_plate(&m, &spectrum, &call, &repeated), Status::Ok);
    assert_eq!(a, b);
    let (mut a, mut b) = (Out::new(n, 4, true), Out::new(n, 4, true));
    a.run_crystal(&m, 7, &l);
    b.run_crystal(&m, 7, &repeated);
    assert_eq!(a, b);

    let refuse = |edit: &dyn Fn(&mut Lanes), out: &mut Out, name: &str| {
        let mut bad = l.clone();
        edit(&mut bad);
        let rc = out.run_plate(&m, &spectrum, &call, &bad);
        assert_eq!(rc, Status::Invalid, "{name}");
        assert!(
            out.message.starts_with(&format!("{name}: ")),
            "{name}: {}",
            out.message
        );
    };
    let mut out = Out::new(n, 4, true);
    refuse(&|b| b.ext_ior = vec![1.0; 3], &mut out, "ext_ior");
    refuse(&|b| b.wi[1].truncate(n - 1), &mut out, "wi");
    refuse(
        &|b| b.wavelengths.push(vec![500.0]),
        &mut out,
        "wavelengths_nm",
    );
    refuse(&|b| b.wavelengths.clear(), &mut out, "wavelengths_nm");
    refuse(&|b| b.material[3] = 99, &mut out, "material");
    refuse(&|b| b.transport[4] = T { repr: 7 }, &mut out, "transport");
    refuse(&|b| b.sample[5] = 1.5, &mut out, "sample");
    refuse(&|b| b.sample[5] = f64::NAN, &mut out, "sample");
    refuse(
        &|b| b.axis_angle_deg = vec![f64::INFINITY],
        &mut out,
        "axis_angle",
    );
    refuse(&|b| b.thickness_nm = vec![-1.0], &mut out, "thickness");
    let mut short = Out::new(n, 4, true);
    short.value[7].truncate(3);
    assert_eq!(short.run_plate(&m, &spectrum, &call, &l), Status::Invalid);
    assert!(short.message.starts_with("value: "), "{}", short.message);
    let mut wrong_channels = Out::new(n, 3, true);
    assert_eq!(
        wrong_channels.run_plate(&m, &spectrum, &call, &l),
        Status::Invalid
    );
    // A channel set takes no wavelength columns.
    let srgb = srgb_spectrum();
    let mut rgb = Out::new(n, 3, true);
    assert_eq!(rgb.run_plate(&m, &srgb, &call, &l), Status::Invalid);
    assert!(
        rgb.message.starts_with("wavelengths_nm: "),
        "{}",
        rgb.message
    );
    for bad in ["xyz-d65", "srgb-d65:Y", "XYZ-D65:Y", "luminance"] {
        let e = colour_channel_spectrum(bad).expect_err(bad).to_string();
        assert!(e.starts_with("channel: must be one of xyz-e:X"), "{e}");
        assert!(e.contains(&format!("got \"{bad}\"")), "{e}");
    }
    // A band is checked per lane, against its wavelength (a quarter of it at most).
    for fwhm in [-1.0, f64::NAN, 200.0] {
        let mut out = Out::new(n, 4, true);
        assert_eq!(
            out.run_plate(&m, &band_spectrum(fwhm), &call, &l),
            Status::Invalid
        );
        assert!(
            out.message.starts_with("filter_bandwidth: "),
            "{}",
            out.message
        );
    }
}

/// Material constructors refuse what the core refuses, naming the parameter.
#[test]
fn material_table_refusals() {
    let mut m = new_materials();
    let e = m
        .add_named("unobtainium", 0.0, 0.0)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("material: unknown crystal 'unobtainium'"),
        "{e}"
    );
    assert!(m
        .add_named("calcite", -1.0, 0.0)
        .unwrap_err()
        .to_string()
        .starts_with("kappa_o:"));
    assert!(m
        .add_constant(f64::NAN, 1.5, 0.0, 0.0)
        .unwrap_err()
        .to_string()
        .starts_with("eta_o:"));
    assert!(m
        .add_constant(1.5, 1.5, 0.0, f64::INFINITY)
        .unwrap_err()
        .to_string()
        .starts_with("kappa_e:"));
    assert_eq!(m.add_constant(1.5, 1.5, 0.0, 0.0).unwrap(), 0);
    assert_eq!(m.add_named("quartz", 0.0, 0.0).unwrap(), 1);
    assert!(m.is_isotropic(0) && !m.is_isotropic(1) && !m.is_isotropic(2));
}
