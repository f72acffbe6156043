//! Validated parameters. Each is checked once, where it enters the core (the bridge for the
//! plugins, the JSON reader for the calculator), with the name and the unit the caller's user
//! wrote, and becomes a value that the constructors inside the core take without checking
//! again. One rule per parameter, here; each boundary passes its own name: the plugin's
//! `thickness` (µm) and `filter_bandwidth`, the calculator's `thickness_um` and
//! `spectrum.bandwidth_nm`.

use crate::error::{Error, Result};
use crate::real::{Mask, Real};

/// Largest plate thickness (nm): 1 m. Beyond, the phases `k d q` (~1e7 rad per metre at
/// 550 nm) lose the digits that interference needs.
pub const THICKNESS_MAX_NM: f64 = 1e9;

/// A unit of length a caller's user gives a thickness in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Length {
    /// Nanometres (the core's unit of lengths and wavelengths).
    Nanometres,
    /// Micrometres.
    Micrometres,
}

impl Length {
    /// Nanometres per unit.
    fn nm(self) -> f64 {
        match self {
            Length::Nanometres => 1.0,
            Length::Micrometres => 1e3,
        }
    }

    fn symbol(self) -> &'static str {
        match self {
            Length::Nanometres => "nm",
            Length::Micrometres => "µm",
        }
    }
}

/// A plate thickness: finite, within `[0, THICKNESS_MAX_NM]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thickness {
    nm: f64,
}

impl Thickness {
    /// The thickness `nm` (nanometres) of the caller's parameter `name`, whose user gives it in
    /// `shown_in`: the message of an invalid value names `name` and speaks `shown_in`.
    pub fn new(name: &str, nm: f64, shown_in: Length) -> Result<Self> {
        if nm.is_finite() && (0.0..=THICKNESS_MAX_NM).contains(&nm) {
            return Ok(Thickness { nm });
        }
        let (unit, per) = (shown_in.symbol(), shown_in.nm());
        Err(Error::new(
            name,
            format!(
                "must be within [0, {:e}] {unit} (1 m), got {} {unit}",
                THICKNESS_MAX_NM / per,
                nm / per
            ),
        ))
    }

    /// [`Thickness::new`] over the reals `T`: the check and its message where the value is
    /// known; while recording, the lanes where it fails carry no light.
    pub fn checked<T: Real>(name: &str, nm: T, shown_in: Length) -> Result<T> {
        if let Some(x) = nm.value() {
            return Thickness::new(name, x, shown_in).map(|_| nm);
        }
        let valid = nm.ge(T::zero()) & nm.le(T::cst(THICKNESS_MAX_NM));
        (!valid).fail(|| Error::new(name, "outside [0, 1 m]"))?;
        Ok(nm)
    }

    /// [`Thickness::new`] of a value given in nanometres under the name `thickness_nm`.
    pub fn from_nm(nm: f64) -> Result<Self> {
        Thickness::new("thickness_nm", nm, Length::Nanometres)
    }

    /// The thickness in nanometres.
    pub fn nm(self) -> f64 {
        self.nm
    }
}

/// The full width at half maximum of a Gaussian band around a wavelength: finite, `>= 0` and
/// at most a quarter of the wavelength (a Gaussian in wavenumber then keeps all its weight far
/// from `k = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bandwidth {
    fwhm_nm: f64,
}

impl Bandwidth {
    /// The FWHM `fwhm_nm` (nm) of the caller's parameter `name` for a band centred on
    /// `wavelength_nm` (a valid wavelength).
    pub fn new(name: &str, fwhm_nm: f64, wavelength_nm: f64) -> Result<Self> {
        let max = 0.25 * wavelength_nm;
        if fwhm_nm.is_finite() && (0.0..=max).contains(&fwhm_nm) {
            return Ok(Bandwidth { fwhm_nm });
        }
        Err(Error::new(
            name,
            format!(
                "must be within [0, {max}] nm (a quarter of the wavelength {wavelength_nm} nm), got {fwhm_nm} nm"
            ),
        ))
    }

    /// The FWHM in nanometres.
    pub fn fwhm_nm(self) -> f64 {
        self.fwhm_nm
    }
}

/// Thinnest plate (nm) that loads without a warning: 10 nm, a few atomic layers. A thickness
/// in metres (Mitsuba's usual scene unit) given for micrometres lands below it for every plate
/// under 1 cm.
pub const THIN_PLATE_NM: f64 = 10.0;

/// Smallest retardance (nm) of a birefringent plate that loads without a warning: below 1 nm,
/// 1/550 of a wave at 550 nm, crossed polarisers pass sin²(π Γ/λ) < 3.3e-5 of the light and the
/// plate looks isotropic. A photoelastic plate whose thickness in millimetres was given as
/// micrometres (3.0 for 3 mm, with a stress birefringence of 2e-4: 0.6 nm) lands below it.
pub const INVISIBLE_RETARDANCE_NM: f64 = 1.0;

/// A warning for a plate whose thickness is probably in the wrong unit, naming the caller's
/// parameter `name` in the unit `shown_in`: thinner than [`THIN_PLATE_NM`] (but not 0, a bare
/// interface pair), or birefringent (`birefringence` = |Re(n_e − n_o)| at 550 nm, with any added
/// stress birefringence; 0 for an isotropic plate) with a retardance `birefringence · d` below
/// [`INVISIBLE_RETARDANCE_NM`]. `None` when neither holds. Such plates are valid; the warning
/// says what the numbers give and where the unit mistake would be.
pub fn thickness_warning(
    name: &str,
    thickness: Thickness,
    shown_in: Length,
    birefringence: f64,
) -> Option<String> {
    let d = thickness.nm();
    let (unit, per) = (shown_in.symbol(), shown_in.nm());
    let unit_hint = format!(
        "{name} is in {unit} (a 3 mm plate is {} {unit}); if this is the plate you mean, ignore \
         this warning",
        3e6 / per
    );
    if d > 0.0 && d < THIN_PLATE_NM {
        return Some(format!(
            "{name}: {} {unit} is thinner than {} {unit} (a few atomic layers), which a \
             thickness in metres would give; {unit_hint}",
            shown(d / per),
            THIN_PLATE_NM / per
        ));
    }
    let retardance = birefringence.abs() * d;
    if d > 0.0 && birefringence != 0.0 && retardance < INVISIBLE_RETARDANCE_NM {
        let wave = 550.0 / retardance;
        let passed = (std::f64::consts::PI * retardance / 550.0).sin().powi(2);
        return Some(format!(
            "{name}: the plate's birefringence {:.3e} (n_e - n_o at 550 nm, with \
             `birefringence`) over {} {unit} is a retardance of {retardance:.3} nm, 1/{wave:.0} \
             of a wave: it looks isotropic (crossed polarisers pass {passed:.1e} of the light); \
             {unit_hint}",
            birefringence.abs(),
            shown(d / per)
        ));
    }
    None
}

/// A warning for an angle in degrees that is probably in radians, naming the caller's
/// parameter `name`: a value within 1 % of a step of a multiple k π/12 of π/12, 1 <= k <= 24 (π/4
/// = 0.785, π/2 = 1.571, π = 3.142, ...), i.e. a round angle in radians that is no round angle
/// in degrees (no integer is that close to one: 1 to 6 degrees miss by 4 % of a step or more).
/// `None` otherwise, and for a non-finite value (the load check refuses it with its message).
pub fn angle_warning(name: &str, degrees: f64) -> Option<String> {
    let step = std::f64::consts::PI / 12.0;
    let k = (degrees.abs() / step).round();
    if !(1.0..=24.0).contains(&k) || (degrees.abs() / step - k).abs() > 0.01 {
        return None;
    }
    let (num, den) = reduced(k as u32, 12);
    let fraction = match (num, den) {
        (1, 1) => "π".to_string(),
        (n, 1) => format!("{n}π"),
        (1, d) => format!("π/{d}"),
        (n, d) => format!("{n}π/{d}"),
    };
    let sign = if degrees < 0.0 { "-" } else { "" };
    Some(format!(
        "{name}: {} degrees is {sign}{fraction} in radians ({sign}{} degrees); {name} is in \
         degrees; if {} degrees is what you mean, ignore this warning",
        shown(degrees),
        k as u32 * 15,
        shown(degrees)
    ))
}

/// `num/den` in lowest terms.
fn reduced(num: u32, den: u32) -> (u32, u32) {
    let (mut a, mut b) = (num, den);
    while b != 0 {
        (a, b) = (b, a % b);
    }
    (num / a, den / a)
}

/// `x` to 6 significant digits, as a message shows a value that went through single precision
/// (a Mitsuba texture's 0.003 is 0.003000000026).
fn shown(x: f64) -> f64 {
    format!("{x:.5e}").parse().unwrap_or(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The limits are inclusive, every message names the caller's parameter in its unit.
    #[test]
    fn limits_and_messages() {
        assert!(Thickness::new("t", 0.0, Length::Micrometres).is_ok());
        assert!(Thickness::new("t", THICKNESS_MAX_NM, Length::Micrometres).is_ok());
        let e = Thickness::new("thickness_um", 2e9, Length::Micrometres).unwrap_err();
        assert_eq!(
            e.to_string(),
            "thickness_um: must be within [0, 1e6] µm (1 m), got 2000000 µm"
        );
        let e = Thickness::from_nm(f64::NAN).unwrap_err();
        assert_eq!(
            e.to_string(),
            "thickness_nm: must be within [0, 1e9] nm (1 m), got NaN nm"
        );
        assert!(Bandwidth::new("b", 100.0, 400.0).is_ok());
        assert!(Bandwidth::new("b", 0.0, 400.0).is_ok());
        for bad in [-1e-300, 100.000_001, f64::NAN, f64::INFINITY] {
            let e = Bandwidth::new("filter_bandwidth", bad, 400.0).unwrap_err();
            assert_eq!(e.parameter, "filter_bandwidth");
            assert!(e.message.contains("[0, 100] nm"), "{e}");
        }
    }

    /// The warnings' thresholds and texts: a thickness in metres, a photoelastic plate in
    /// millimetres given as micrometres; plates on the right side of each threshold, a bare
    /// interface pair (0) and isotropic plates pass silently.
    #[test]
    fn thickness_warnings() {
        let um = |x: f64| Thickness::new("thickness", x * 1e3, Length::Micrometres).unwrap();
        let warn = |x: f64, b: f64| thickness_warning("thickness", um(x), Length::Micrometres, b);
        // 3 mm written in metres: 0.003 um.
        let w = warn(0.003, 0.0).unwrap();
        assert!(
            w.starts_with("thickness: 0.003 µm is thinner than 0.01 µm"),
            "{w}"
        );
        assert!(w.contains("a 3 mm plate is 3000 µm"), "{w}");
        // As a single-precision texture holds it.
        let w = warn(0.003_f32 as f64, 0.0).unwrap();
        assert!(w.starts_with("thickness: 0.003 µm is"), "{w}");
        assert!(warn(0.0101, 0.0).is_none());
        assert!(warn(0.0, 0.0).is_none() && warn(0.0, 0.2).is_none());
        // 3 mm of stressed glass written as 3: 0.6 nm of retardance.
        let w = warn(3.0, 2e-4).unwrap();
        assert!(
            w.contains("a retardance of 0.600 nm, 1/917 of a wave"),
            "{w}"
        );
        assert!(warn(3000.0, 2e-4).is_none());
        assert!(warn(5.01, 2e-4).is_none()); // 1.002 nm
        assert!(warn(4.99, -2e-4).is_some()); // the sign does not matter
        assert!(warn(3.0, 0.0).is_none()); // an isotropic film
        assert!(warn(1.0, 0.17).is_none()); // 1 um of calcite: 170 nm
    }

    /// Round angles in radians are caught, round angles in degrees (and a textured 0) are not.
    /// The approximations are the point: they are what users type for π/2, π and 2π.
    #[test]
    #[allow(clippy::approx_constant)]
    fn angle_warnings() {
        let w = angle_warning("axis_angle", std::f64::consts::FRAC_PI_4).unwrap();
        assert_eq!(
            w,
            "axis_angle: 0.785398 degrees is π/4 in radians (45 degrees); axis_angle is in \
             degrees; if 0.785398 degrees is what you mean, ignore this warning"
        );
        assert!(angle_warning("a", 0.785)
            .unwrap()
            .contains("π/4 in radians (45 degrees)"));
        assert!(angle_warning("a", -1.5708)
            .unwrap()
            .contains("-π/2 in radians (-90 degrees)"));
        assert!(angle_warning("a", 3.1416)
            .unwrap()
            .contains("is π in radians (180 degrees)"));
        assert!(angle_warning("a", 6.2832)
            .unwrap()
            .contains("2π in radians (360 degrees)"));
        assert!(angle_warning("a", 2.0944)
            .unwrap()
            .contains("2π/3 in radians"));
        for quiet in [
            0.0,
            1.0,
            2.0,
            3.0,
            4.0,
            5.0,
            6.0,
            0.5,
            0.79,
            7.0,
            15.0,
            45.0,
            90.0,
            f64::NAN,
        ] {
            assert!(angle_warning("a", quiet).is_none(), "{quiet}");
        }
    }
}
