//! The boundary with the C++ shim: a `cxx` bridge, from which `cxx` generates the C++ header
//! (`birefringent/src/ffi/mod.rs.h`), so that no declaration or constant is written twice.
//!
//! The shim asks one question per surface point: which lobe does this path follow, and with
//! what weight. Queries come in batches of lanes (structure of arrays, doubles; a column holds
//! one value per lane or one value for all), which is what Mitsuba's JIT variants hand a BSDF
//! (the lanes that hit one instance); the scalar variants send batches of one lane. Each lane
//! is computed exactly as the scalar query (`render::plate::plate_lobes`,
//! `render::stack::stack_lobes` or `render::crystal::crystal_slots`, then
//! `render::choice::choose`), bit for bit, whatever the other lanes of the batch hold.
//!
//! Rules: every function catches panics (a panic crossing the bridge would abort); invalid
//! input is reported as [`bridge::Status::Invalid`] with a message naming the parameter, a
//! defect as [`bridge::Status::Internal`]; no non-finite number is ever written to an output.

mod batch;
mod columns;
mod guard;
mod materials;
mod programs;
mod samples;
mod spectrum;
mod stack;

pub use batch::{sample_crystal, sample_plate};
pub use materials::{new_materials, Materials};
pub use programs::{record_crystal, record_plate, record_stack, Program};
pub use spectrum::{
    band_spectrum, channels_to_linear_srgb, colour_channel_spectrum, colour_channel_wavelength,
    default_channel, exact_spectrum, srgb_spectrum, PlateSpectrum,
};
pub use stack::sample_stack;

/// The library's version.
pub fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[cxx::bridge(namespace = "bfr")]
pub mod bridge {
    /// How a call, or one lane of it, ended.
    #[repr(u8)]
    #[derive(Debug)]
    enum Status {
        /// Success.
        Ok = 0,
        /// Invalid input; the message names the parameter.
        Invalid = 1,
        /// A defect of the core (a caught panic or a non-finite result).
        Internal = 2,
    }

    /// Mitsuba's `TransportMode`.
    #[repr(u8)]
    #[derive(Debug)]
    enum Transport {
        /// Paths traced from the camera.
        Radiance = 0,
        /// Paths traced from the lights.
        Importance = 1,
    }

    /// Array bounds of the queries.
    enum Bounds {
        /// Most channels of one query (the wavelengths Mitsuba's spectral variants trace).
        MaxChannels = 4,
        /// Mitsuba components of a plate: 0 reflection, 1 transmission.
        PlateComponents = 2,
        /// Mitsuba components of a crystal surface: 0 reflection, 1 ordinary and 2
        /// extraordinary refraction.
        CrystalComponents = 3,
    }

    /// Per-call settings of a plate query.
    #[derive(Debug)]
    struct PlateCall {
        /// The Mitsuba components the context enables: bit k for component k.
        components: u32,
        /// Only the unpolarised throughput (`value[0]`) is wanted.
        intensity_only: bool,
        /// The exit medium absorbs whatever enters it (a film on a black substrate): no
        /// transmission and no light from below.
        absorbing_exit: bool,
    }

    /// The lanes of a plate query. Every column holds `count` values (one per lane) or one
    /// (the same for every lane). Local shading frame: z is the normal towards the exterior,
    /// the exterior medium is above the plate and the exit medium below.
    #[derive(Debug)]
    struct PlateLanes<'a> {
        /// Number of lanes.
        count: usize,
        /// 0 for a lane to skip (its outputs are zero), else 1.
        active: &'a [u8],
        /// Index of the lane's material in the `Materials` table.
        material: &'a [u32],
        /// The lane's transport mode.
        transport: &'a [Transport],
        /// A uniform number in [0, 1) that chooses the lobe.
        sample: &'a [f64],
        /// Mitsuba's `si.wi` (unit, local).
        wi: [&'a [f64]; 3],
        /// Wavelengths (nm), one column per channel, for exact and band spectra; none for a
        /// channel set.
        wavelengths_nm: &'a [&'a [f64]],
        /// Real index of the exterior (z > 0).
        ext_ior: &'a [f64],
        /// Real index of the exit medium (below the plate).
        exit_ior: &'a [f64],
        /// Optic axis (local, any non-zero length), before `axis_angle_deg`.
        optic_axis: [&'a [f64]; 3],
        /// Degrees by which the optic axis is rotated about the normal, counter-clockwise seen
        /// from the exterior (the plugin's `axis_angle`); 0 for none.
        axis_angle_deg: &'a [f64],
        /// Thickness (nm): the plugin's `thickness` (micrometres) times `thickness_scale` (its
        /// errors speak micrometres), within [0, 1 m].
        thickness_nm: &'a [f64],
        /// Added to the extraordinary index (photoelastic stress); 0 for none.
        birefringence: &'a [f64],
    }

    /// The lanes of a stack query: the per-lane columns of `PlateLanes`, and per layer (in
    /// order from the exterior down) its material, optic axis and one column each of axis
    /// angles, thicknesses and added birefringences (`count` values, or one for every lane).
    #[derive(Debug)]
    struct StackLanes<'a> {
        /// Number of lanes.
        count: usize,
        /// 0 for a lane to skip (its outputs are zero), else 1.
        active: &'a [u8],
        /// The lane's transport mode.
        transport: &'a [Transport],
        /// A uniform number in [0, 1) that chooses the lobe.
        sample: &'a [f64],
        /// Mitsuba's `si.wi` (unit, local).
        wi: [&'a [f64]; 3],
        /// Wavelengths (nm), one column per channel, for exact and band spectra; none for a
        /// channel set.
        wavelengths_nm: &'a [&'a [f64]],
        /// Real index of the exterior (z > 0).
        ext_ior: &'a [f64],
        /// Real index of the exit medium (below the stack).
        exit_ior: &'a [f64],
        /// Per layer: the index of its material in the `Materials` table.
        material: &'a [u32],
        /// Per layer: its optic axis (local, any non-zero length), before its axis angle.
        optic_axis: [&'a [f64]; 3],
        /// Per layer, a column: degrees by which its optic axis is rotated about the normal.
        axis_angle_deg: &'a [&'a [f64]],
        /// Per layer, a column: its thickness (nm), within [0, 1 m].
        thickness_nm: &'a [&'a [f64]],
        /// Per layer, a column: added to its extraordinary index; 0 for none.
        birefringence: &'a [&'a [f64]],
    }

    /// The lanes of a bulk crystal query (crystal below the surface, z < 0); columns as in
    /// `PlateLanes`.
    #[derive(Debug)]
    struct CrystalLanes<'a> {
        /// Number of lanes.
        count: usize,
        /// 0 for a lane to skip (its outputs are zero), else 1.
        active: &'a [u8],
        /// Index of the lane's material in the `Materials` table.
        material: &'a [u32],
        /// The lane's transport mode.
        transport: &'a [Transport],
        /// A uniform number in [0, 1) that chooses the lobe.
        sample: &'a [f64],
        /// Mitsuba's `si.wi` (unit, local; z < 0 inside the crystal).
        wi: [&'a [f64]; 3],
        /// Wavelengths (nm), one column per channel (at least one).
        wavelengths_nm: &'a [&'a [f64]],
        /// Real index of the exterior (z > 0).
        ext_ior: &'a [f64],
        /// Optic axis (local, any non-zero length).
        optic_axis: [&'a [f64]; 3],
    }

    /// The lobe each lane samples, as Mitsuba's `BSDFSample3f` and sample weight need it.
    /// Per-lane columns hold `count` values; per-channel columns `channels * count`, channel
    /// c of lane i at `c * count + i`. The optional columns (`in_stokes_x`, `out_stokes_x`,
    /// `value[1..16]`) may be empty, and are then not written. A lane that samples nothing
    /// (inactive, no lobe enabled, or an error) has `pdf` 0 and zero everywhere else.
    ///
    /// Physically the light arrives along `-wo_hat` and leaves along `wi_hat`, where
    /// `(wo_hat, wi_hat) = (wo, wi)` in Radiance mode and `(wi, wo)` in Importance mode. A
    /// Stokes frame is given by its x axis; y = (propagation direction) x (x axis).
    #[derive(Debug)]
    struct Samples<'a> {
        /// How each lane ended.
        status: &'a mut [Status],
        /// Mitsuba's `sampled_component`.
        component: &'a mut [u32],
        /// Probability of choosing this lobe (1 when it is the only candidate).
        pdf: &'a mut [f64],
        /// Mitsuba's `bs.eta`: ray index on the `wo` side over the `wi` side.
        eta: &'a mut [f64],
        /// Mitsuba's `bs.wo` (unit, local): the direction of the first channel that has the
        /// lobe (with dispersion the other channels follow it).
        wo: [&'a mut [f64]; 3],
        /// Per channel: x axis of the Stokes frame of the light arriving along `-wo_hat`.
        in_stokes_x: [&'a mut [f64]; 3],
        /// Per channel: x axis of the Stokes frame of the light leaving along `wi_hat`.
        out_stokes_x: [&'a mut [f64]; 3],
        /// Per channel: the sample weight, the lobe's Mueller matrix (row-major, Mitsuba's
        /// convention, power fractions, in Radiance mode with the radiance factor) divided by
        /// `pdf`; zero in a channel without the lobe (whose frames are then the first
        /// channel's).
        value: [&'a mut [f64]; 16],
        /// The message of the first lane (or call) that failed.
        message: String,
    }

    /// An operation of a recorded program (`crate::record::Op`, in the same order): numbers
    /// are Dr.Jit floats, masks Dr.Jit masks.
    #[repr(u8)]
    #[derive(Debug)]
    enum Op {
        Const = 0,
        Input,
        Neg,
        Add,
        Sub,
        Mul,
        Div,
        Sqrt,
        SafeSqrt,
        Sin,
        Cos,
        Exp,
        Abs,
        Min,
        Max,
        CopySign,
        Detach,
        Select,
        Lt,
        Le,
        Eq,
        Finite,
        And,
        Or,
        Not,
        Flag,
    }

    /// One instruction of a recorded program: its result is value number `i`, its position.
    /// Operands are earlier value numbers (`a` is the input's index for `Input`); `value` is
    /// the constant of `Const` and `Flag` (nonzero: true).
    #[derive(Debug)]
    struct Instr {
        op: Op,
        a: u32,
        b: u32,
        c: u32,
        value: f64,
    }

    /// The inputs of a plate's program, by index. The texture values and the path's are
    /// always read; the material's and the axis only where the recipe makes them inputs
    /// (otherwise the recipe's values are constants of the program).
    #[repr(u32)]
    #[derive(Debug)]
    enum PlateInput {
        /// Mitsuba's si.wi (local frame).
        WiX = 0,
        WiY = 1,
        WiZ = 2,
        /// The lobe-choosing uniform number.
        Sample = 3,
        /// The thickness texture's value (um, before thickness_scale).
        Thickness = 4,
        /// The birefringence texture's value (before birefringence_scale), where it has one.
        Birefringence = 5,
        /// The axis_angle texture's value (degrees), where it has one.
        AxisAngle = 6,
        /// optic_axis (where `axis_is_input`).
        AxisX = 7,
        AxisY = 8,
        AxisZ = 9,
        /// Re eta_o, Re eta_e of constant indices (where `indices_are_inputs`).
        EtaO = 10,
        EtaE = 11,
        /// kappa_o, kappa_e (where `kappas_are_inputs`).
        KappaO = 12,
        KappaE = 13,
        /// The first of `channels` wavelengths (nm).
        Wavelength0 = 14,
    }

    /// The outputs of a sample program, by index: the mask `Valid` (a lobe was sampled), then
    /// numbers; per channel `c` (always 4, a query of fewer repeating its last) at
    /// `Channel0 + PerChannel c`: the in and out Stokes x axes (3 + 3), then the Mueller matrix
    /// over the pdf, row-major (16). After `Count` outputs, one more: the mask of the lanes
    /// that could not be computed (an invalid texture value), which carry no light.
    #[repr(u32)]
    #[derive(Debug)]
    enum SampleOutput {
        Valid = 0,
        Slot = 1,
        Component = 2,
        Pdf = 3,
        Eta = 4,
        WoX = 5,
        WoY = 6,
        WoZ = 7,
        Channel0 = 8,
        PerChannel = 22,
        Count = 96,
    }

    /// What a plate's program is recorded for: the query's settings and the plugin's
    /// parameters (which of them are inputs, the others' values as constants).
    #[derive(Debug)]
    struct PlateRecipe {
        material: u32,
        transport: Transport,
        components: u32,
        channels: u32,
        intensity_only: bool,
        absorbing_exit: bool,
        ext_ior: f64,
        exit_ior: f64,
        thickness_scale: f64,
        /// The plate has a `birefringence` texture (else its input is not read).
        has_birefringence: bool,
        birefringence_scale: f64,
        /// The plate has an `axis_angle` texture (else its input is not read).
        has_axis_angle: bool,
        optic_axis: [f64; 3],
        axis_is_input: bool,
        indices_are_inputs: bool,
        kappas_are_inputs: bool,
    }

    /// The path's inputs of a stack's program, by index: `wi`, the sample, four wavelength
    /// slots (a program of fewer channels reads the first ones), then from `Layer0` one block
    /// of `StackLayerInput::Stride` inputs per layer, from the exterior down (layer k's input
    /// i at `Layer0 + k * Stride + i`).
    #[repr(u32)]
    #[derive(Debug)]
    enum StackInput {
        /// Mitsuba's si.wi (local frame).
        WiX = 0,
        WiY = 1,
        WiZ = 2,
        /// The lobe-choosing uniform number.
        Sample = 3,
        /// The first of `channels` wavelengths (nm).
        Wavelength0 = 4,
        /// The first layer's block.
        Layer0 = 8,
    }

    /// The inputs of one layer of a stack's program, within its block (`StackInput`): as a
    /// plate's (`PlateInput`). The thickness is always read, the other textures' values where
    /// the layer has them; the axis, the indices and the extinctions where the layer's recipe
    /// makes them inputs.
    #[repr(u32)]
    #[derive(Debug)]
    enum StackLayerInput {
        /// The layer's thickness texture value (um, before its thickness_scale).
        Thickness = 0,
        /// Its birefringence texture value (before its birefringence_scale), where it has one.
        Birefringence = 1,
        /// Its axis_angle texture value (degrees), where it has one.
        AxisAngle = 2,
        /// Its optic_axis (where `axis_is_input`).
        AxisX = 3,
        AxisY = 4,
        AxisZ = 5,
        /// Re eta_o, Re eta_e of constant indices (where `indices_are_inputs`).
        EtaO = 6,
        EtaE = 7,
        /// kappa_o, kappa_e (where `kappas_are_inputs`).
        KappaO = 8,
        KappaE = 9,
        /// Inputs per layer.
        Stride = 10,
    }

    /// What one layer of a stack's program is recorded for: a nested plate's parameters as in
    /// `PlateRecipe` (which of them are inputs, the others' values as constants).
    #[derive(Debug)]
    struct StackLayerRecipe {
        material: u32,
        thickness_scale: f64,
        /// The layer has a `birefringence` texture (else its input is not read).
        has_birefringence: bool,
        birefringence_scale: f64,
        /// The layer has an `axis_angle` texture (else its input is not read).
        has_axis_angle: bool,
        optic_axis: [f64; 3],
        axis_is_input: bool,
        indices_are_inputs: bool,
        kappas_are_inputs: bool,
    }

    /// What a stack's program is recorded for: the query's settings, the media around the stack
    /// and its layers from the exterior down (at least one).
    #[derive(Debug)]
    struct StackRecipe {
        transport: Transport,
        components: u32,
        channels: u32,
        intensity_only: bool,
        absorbing_exit: bool,
        ext_ior: f64,
        exit_ior: f64,
        layers: Vec<StackLayerRecipe>,
    }

    extern "Rust" {
        /// Records the sample of a stack over `recipe.channels` exact wavelengths; outputs as
        /// `record_plate`'s (`SampleOutput`).
        fn record_stack(materials: &Materials, recipe: &StackRecipe) -> Result<Box<Program>>;
    }

    /// The inputs of a crystal surface's program, by index. The path's values are always
    /// read; the material's and the axis only where the recipe makes them inputs (otherwise
    /// the recipe's values are constants of the program).
    #[repr(u32)]
    #[derive(Debug)]
    enum CrystalInput {
        /// Mitsuba's si.wi (local frame; z < 0 inside the crystal).
        WiX = 0,
        WiY = 1,
        WiZ = 2,
        /// The lobe-choosing uniform number.
        Sample = 3,
        /// optic_axis (where `axis_is_input`; any non-zero length).
        AxisX = 4,
        AxisY = 5,
        AxisZ = 6,
        /// Re eta_o, Re eta_e of constant indices (where `indices_are_inputs`).
        EtaO = 7,
        EtaE = 8,
        /// kappa_o, kappa_e (where `kappas_are_inputs`).
        KappaO = 9,
        KappaE = 10,
        /// The first of `channels` wavelengths (nm).
        Wavelength0 = 11,
    }

    /// What a crystal surface's program is recorded for: the query's settings and the plugin's
    /// parameters (which of them are inputs, the others' values as constants). The outputs
    /// are `SampleOutput`'s; the slots are the crystal's (0 reflection, 1 and 2 the o and e
    /// refractions from outside, 3-5 and 6-8 the lobes of light arriving as the o- and the
    /// e-ray from inside).
    #[derive(Debug)]
    struct CrystalRecipe {
        material: u32,
        transport: Transport,
        components: u32,
        channels: u32,
        intensity_only: bool,
        ext_ior: f64,
        optic_axis: [f64; 3],
        axis_is_input: bool,
        indices_are_inputs: bool,
        kappas_are_inputs: bool,
    }

    extern "Rust" {
        /// Records the sample of a crystal surface over `recipe.channels` exact wavelengths
        /// (one in the RGB and mono variants: the channel's mean, `colour_channel_wavelength`).
        fn record_crystal(materials: &Materials, recipe: &CrystalRecipe) -> Result<Box<Program>>;
    }

    extern "Rust" {
        /// A recorded program (`crate::record::Program`).
        type Program;
        /// Records the sample of a plate over `recipe.channels` exact wavelengths.
        fn record_plate(materials: &Materials, recipe: &PlateRecipe) -> Result<Box<Program>>;
        /// The instructions, operands before their uses.
        fn instructions(self: &Program) -> &[Instr];
        /// The value numbers of the outputs, in `SampleOutput` order, then the failure mask.
        fn outputs(self: &Program) -> &[u32];
        /// How many inputs it reads.
        fn inputs(self: &Program) -> usize;
        /// Instructions other than constants and inputs.
        fn operations(self: &Program) -> usize;
    }

    extern "Rust" {
        /// A table of materials; lanes refer to them by index.
        type Materials;
        /// An empty table.
        fn new_materials() -> Box<Materials>;
        /// Appends a named crystal (see the calculator's docs) with extinction added to its
        /// ordinary and extraordinary indices (>= 0); returns its index.
        fn add_named(self: &mut Materials, name: &str, kappa_o: f64, kappa_e: f64) -> Result<u32>;
        /// Appends constant indices `eta_o + i kappa_o`, `eta_e + i kappa_e`; returns its index.
        fn add_constant(
            self: &mut Materials,
            eta_o: f64,
            eta_e: f64,
            kappa_o: f64,
            kappa_e: f64,
        ) -> Result<u32>;
        /// True if material `index` is isotropic at every wavelength (equal constant indices).
        fn is_isotropic(self: &Materials, index: u32) -> bool;
        /// The warning to show when material `index` is loaded, empty if none: a named crystal
        /// whose cited data do not cover 360-830 nm (where Mitsuba samples), so that its fit is
        /// extrapolated there.
        fn warning(self: &Materials, index: u32) -> String;
        /// The warning to show when a plate of material `index`, `thickness_nm` thick (the
        /// plugin's `thickness` times `thickness_scale`, in nm), with `birefringence` added to
        /// Re eta_e and rotated by `axis_angle_deg` (NaN: none given, or a texture) is loaded,
        /// empty if none: a thickness probably in the wrong unit (thinner than 10 nm, or a
        /// birefringent plate with a retardance below 1 nm at 550 nm) or an angle probably in
        /// radians (see `params::thickness_warning`, `params::angle_warning`).
        fn plate_warning(
            self: &Materials,
            index: u32,
            thickness_nm: f64,
            birefringence: f64,
            axis_angle_deg: f64,
        ) -> String;

        /// What spectrum a plate is evaluated over.
        type PlateSpectrum;
        /// Exact at each lane's wavelengths.
        fn exact_spectrum() -> Box<PlateSpectrum>;
        /// Closed-form average over a Gaussian band of full width at half maximum `fwhm_nm`
        /// (the plugin's `filter_bandwidth`; 0 is exact) around each lane's wavelengths,
        /// checked per lane: within [0, a quarter of the wavelength].
        fn band_spectrum(fwhm_nm: f64) -> Box<PlateSpectrum>;
        /// Closed-form integral over the three linear sRGB channels under D65 (signed weights;
        /// no wavelengths): the RGB variants. Each channel is normalised so that a spectrally
        /// flat response of 1 gives 1.
        fn srgb_spectrum() -> Box<PlateSpectrum>;
        /// Closed-form integral over one colour channel named `"<weights>:<channel>"` (the
        /// plugins' `channel` parameter: `srgb-d65` R, G, B; `xyz-d65` or `xyz-e` X, Y, Z; no
        /// wavelengths): the mono variants, one channel per render.
        fn colour_channel_spectrum(name: &str) -> Result<Box<PlateSpectrum>>;
        /// The plugins' default `channel` in the mono variants: `"xyz-d65:Y"`, the luminance.
        fn default_channel() -> &'static str;
        /// The wavelength (nm) at which a render of channel `name` evaluates a bulk crystal
        /// (its refraction's directions depend on the wavelength): the channel's mean.
        fn colour_channel_wavelength(name: &str) -> Result<f64>;
        /// Channels of a query with `wavelengths` wavelength columns.
        fn channels(self: &PlateSpectrum, wavelengths: usize) -> usize;
        /// Why a query over this spectrum has no derivatives (empty: it has them).
        fn gradients_refused(self: &PlateSpectrum) -> String;

        /// Samples a plate lobe (slot 0 reflection, 1 transmission) in every lane. Returns
        /// `Ok` if every lane succeeded, else the status of the first failure (the call's own,
        /// e.g. a column of the wrong length, or a lane's) with its message in `out.message`.
        fn sample_plate(
            materials: &Materials,
            spectrum: &PlateSpectrum,
            call: &PlateCall,
            lanes: &PlateLanes,
            out: &mut Samples,
        ) -> Status;

        /// Samples a stack lobe (slot 0 reflection, 1 transmission) in every lane; returns as
        /// `sample_plate`.
        fn sample_stack(
            materials: &Materials,
            spectrum: &PlateSpectrum,
            call: &PlateCall,
            lanes: &StackLanes,
            out: &mut Samples,
        ) -> Status;

        /// Samples a crystal lobe in every lane, with the components in the bits of
        /// `components` enabled; returns as `sample_plate`.
        fn sample_crystal(
            materials: &Materials,
            components: u32,
            lanes: &CrystalLanes,
            out: &mut Samples,
        ) -> Status;

        /// The library's version.
        fn version() -> &'static str;
    }
}
