//! The networks' architectures and a plain-Rust forward pass of their trained weights.
//!
//! Training runs on burn (`spdcam_learn::train`); estimating does not need it: a [`Network`]
//! holds the weights as plain arrays and computes its output with a few matrix products
//! (faer), with no autodiff bookkeeping. The layouts are channels-last:
//!
//! - a dense layer's weight is `[inputs, outputs]` row-major, its bias `[outputs]`;
//! - a 1D convolution over `[positions, channels]` is a dense layer applied to each window
//!   of `kernel` positions, flattened position-major: weight `[kernel · in_channels, filters]`;
//! - max pooling takes the largest value of each run of `pool` positions, per channel
//!   (a trailing partial run is dropped, like Keras's `MaxPooling1D`).

use crate::error::{InferError, Result};
use faer::{linalg::matmul::matmul, Accum, MatMut, MatRef, Par};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The thesis's 1D CNN (Table 4.5): Conv1D(32, 7, ReLU) → Conv1D(64, 5, ReLU) → MaxPool(2) →
/// Dropout(0.2) → Flatten → Dense(64, ReLU) → Dense(outputs, sigmoid).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CnnSpec {
    /// Filters of the first convolution.
    pub conv1_filters: usize,
    /// Kernel length of the first convolution.
    pub conv1_kernel: usize,
    /// Filters of the second convolution.
    pub conv2_filters: usize,
    /// Kernel length of the second convolution.
    pub conv2_kernel: usize,
    /// Max-pooling size (and stride).
    pub pool: usize,
    /// Dropout probability after the pooling (training only).
    pub dropout: f64,
    /// Units of the hidden dense layer.
    pub dense: usize,
}

impl CnnSpec {
    /// The thesis's network, Table 4.5.
    pub fn thesis() -> CnnSpec {
        CnnSpec {
            conv1_filters: 32,
            conv1_kernel: 7,
            conv2_filters: 64,
            conv2_kernel: 5,
            pool: 2,
            dropout: 0.2,
            dense: 64,
        }
    }

    /// Positions after the first convolution, the second, and the pooling, for `inputs`
    /// features; an error when the input is too short for the kernels.
    pub fn lengths(&self, inputs: usize) -> Result<[usize; 3]> {
        let too_short = || {
            InferError::invalid(format!(
                "the 1D CNN needs at least {} input features, got {inputs}",
                self.conv1_kernel + self.conv2_kernel + self.pool - 2
            ))
        };
        let l1 = (inputs + 1)
            .checked_sub(self.conv1_kernel)
            .filter(|&l| l > 0);
        let l1 = l1.ok_or_else(too_short)?;
        let l2 = (l1 + 1).checked_sub(self.conv2_kernel).filter(|&l| l > 0);
        let l2 = l2.ok_or_else(too_short)?;
        let l3 = l2 / self.pool.max(1);
        if l3 == 0 {
            return Err(too_short());
        }
        Ok([l1, l2, l3])
    }
}

/// The thesis's DNN (Table 4.1): dense ReLU layers 32-32-64-64-128-128-256-256-512-512, then
/// a dense sigmoid output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MlpSpec {
    /// Units of each hidden layer.
    pub hidden: Vec<usize>,
    /// Dropout probability after each hidden layer (training only).
    pub dropout: f64,
}

impl MlpSpec {
    /// The thesis's network, Table 4.1.
    pub fn thesis() -> MlpSpec {
        MlpSpec {
            hidden: vec![32, 32, 64, 64, 128, 128, 256, 256, 512, 512],
            dropout: 0.0,
        }
    }
}

/// A network's layers (not its size, which the data fix).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Architecture {
    /// The 1D CNN.
    Cnn1d(CnnSpec),
    /// The multilayer perceptron.
    Mlp(MlpSpec),
    /// Ridge regression, fitted in closed form: one dense layer with no activation.
    Linear {
        /// The ridge penalty λ (on normalised features).
        ridge: f64,
    },
    /// The mean of the outputs of trained networks that share the model's scalings and
    /// target (an ensemble, made by `spdcam average`): averaging learners that err
    /// differently cancels part of their errors (Breiman 1996, "Bagging predictors", Machine
    /// Learning 24: 123–140; here a network and a ridge, which fail on different photos).
    Average {
        /// The members, each a network or ridge (not an average).
        members: Vec<Architecture>,
    },
}

impl Architecture {
    /// The short name used on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Architecture::Cnn1d(_) => "cnn1d",
            Architecture::Mlp(_) => "mlp",
            Architecture::Linear { .. } => "linear",
            Architecture::Average { .. } => "average",
        }
    }

    /// Whether it is trained (and fine-tuned) by gradient descent: the networks, not the
    /// closed-form ridge nor an average of trained models.
    pub fn trained_by_gradient(&self) -> bool {
        matches!(self, Architecture::Cnn1d(_) | Architecture::Mlp(_))
    }

    /// A short description: the name, and an average's members.
    pub fn label(&self) -> String {
        match self {
            Architecture::Average { members } => format!(
                "average of {}",
                members
                    .iter()
                    .map(|m| m.label())
                    .collect::<Vec<_>>()
                    .join(" and ")
            ),
            other => other.name().to_string(),
        }
    }

    /// Names and shapes of the parameters for `inputs` features and `outputs` targets, in
    /// forward order.
    pub fn parameter_shapes(
        &self,
        inputs: usize,
        outputs: usize,
    ) -> Result<Vec<(String, Vec<usize>)>> {
        if inputs == 0 || outputs == 0 {
            return Err(InferError::invalid(format!(
                "a network needs inputs and outputs, got {inputs} and {outputs}"
            )));
        }
        let mut shapes = Vec::new();
        let mut dense = |name: &str, i: usize, o: usize| {
            shapes.push((format!("{name}.weight"), vec![i, o]));
            shapes.push((format!("{name}.bias"), vec![o]));
        };
        match self {
            Architecture::Cnn1d(s) => {
                let [_, _, l3] = s.lengths(inputs)?;
                dense("conv1", s.conv1_kernel, s.conv1_filters);
                dense("conv2", s.conv2_kernel * s.conv1_filters, s.conv2_filters);
                dense("dense", l3 * s.conv2_filters, s.dense);
                dense("output", s.dense, outputs);
            }
            Architecture::Mlp(s) => {
                let mut width = inputs;
                for (i, &h) in s.hidden.iter().enumerate() {
                    dense(&format!("hidden{i}"), width, h);
                    width = h;
                }
                dense("output", width, outputs);
            }
            Architecture::Linear { .. } => dense("output", inputs, outputs),
            Architecture::Average { members } => {
                for (i, member) in members.iter().enumerate() {
                    for (name, shape) in member.parameter_shapes(inputs, outputs)? {
                        shapes.push((format!("m{i}.{name}"), shape));
                    }
                }
            }
        }
        Ok(shapes)
    }

    /// Checks the settings are usable.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(InferError::invalid(m));
        match self {
            Architecture::Cnn1d(s) => {
                if [
                    s.conv1_filters,
                    s.conv1_kernel,
                    s.conv2_filters,
                    s.conv2_kernel,
                    s.pool,
                    s.dense,
                ]
                .contains(&0)
                {
                    return bad(format!("a 1D CNN layer size is 0: {s:?}"));
                }
                if !(0.0..1.0).contains(&s.dropout) {
                    return bad(format!("dropout {} must lie in [0, 1)", s.dropout));
                }
            }
            Architecture::Mlp(s) => {
                if s.hidden.contains(&0) {
                    return bad(format!("an MLP layer has 0 units: {:?}", s.hidden));
                }
                if !(0.0..1.0).contains(&s.dropout) {
                    return bad(format!("dropout {} must lie in [0, 1)", s.dropout));
                }
            }
            Architecture::Linear { ridge } => {
                if !(ridge.is_finite() && *ridge >= 0.0) {
                    return bad(format!("the ridge penalty {ridge} must be ≥ 0"));
                }
            }
            Architecture::Average { members } => {
                if members.len() < 2 {
                    return bad(format!(
                        "an average needs at least two members, got {}",
                        members.len()
                    ));
                }
                for member in members {
                    if let Architecture::Average { .. } = member {
                        return bad("an average's member is itself an average".into());
                    }
                    member.validate()?;
                }
            }
        }
        Ok(())
    }
}

/// One named parameter array.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// `layer.weight` or `layer.bias`.
    pub name: String,
    /// The array's shape.
    pub shape: Vec<usize>,
    /// The values, row-major.
    pub data: Vec<f32>,
}

/// A network with its weights, ready to compute outputs from normalised features.
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    architecture: Architecture,
    inputs: usize,
    outputs: usize,
    parameters: Vec<Parameter>,
    /// An average's members (their parameters without the `m{i}.` prefix); empty otherwise.
    members: Vec<Network>,
}

/// Rows per block of a batched forward pass (blocks run in parallel).
const BLOCK_ROWS: usize = 256;

fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

/// Marks the upper halves of the 256-bit vector registers unused (`vzeroupper`) after faer's
/// AVX kernels, which return without doing so. Until then every scalar SSE instruction that
/// follows on the thread (the bias loop, libm's `expf` in the sigmoid, the decoding after the
/// network) waits on the upper halves' state: on this project's benchmark machine a sigmoid
/// after a matrix product took 135 ns instead of 5 ns. Intel® 64 and IA-32 Architectures
/// Optimization Reference Manual (2023), §15.3 "Mixing AVX code with SSE code".
fn clear_upper_vector_state() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU supports AVX, as checked just above; `vzeroupper` only clears the
        // upper halves of registers that hold no live value between these calls.
        unsafe { std::arch::x86_64::_mm256_zeroupper() }
    }
}

/// `out[rows, o] = act(x[rows, i] · w[i, o] + b)`, `x` viewed with row stride `x_stride`.
#[allow(clippy::too_many_arguments)]
fn dense_into(
    x: &[f32],
    rows: usize,
    i: usize,
    x_stride: usize,
    w: &Parameter,
    b: &Parameter,
    out: &mut [f32],
    relu: bool,
) {
    let o = b.data.len();
    let lhs = MatRef::from_row_major_slice_with_stride(x, rows, i, x_stride);
    let rhs = MatRef::from_row_major_slice(&w.data, i, o);
    let dst = MatMut::from_row_major_slice_mut(&mut out[..rows * o], rows, o);
    matmul(dst, Accum::Replace, lhs, rhs, 1.0f32, Par::Seq);
    clear_upper_vector_state();
    for row in out[..rows * o].chunks_exact_mut(o) {
        for (v, bias) in row.iter_mut().zip(&b.data) {
            *v += bias;
            if relu && *v < 0.0 {
                *v = 0.0;
            }
        }
    }
}

impl Network {
    /// A network from its parameters; an error when a name or shape does not fit the
    /// architecture, or a value is not finite.
    pub fn new(
        architecture: Architecture,
        inputs: usize,
        outputs: usize,
        parameters: Vec<Parameter>,
    ) -> Result<Network> {
        architecture.validate()?;
        let shapes = architecture.parameter_shapes(inputs, outputs)?;
        if shapes.len() != parameters.len() {
            return Err(InferError::invalid(format!(
                "the {} network needs {} parameter arrays, got {}",
                architecture.name(),
                shapes.len(),
                parameters.len()
            )));
        }
        for ((name, shape), p) in shapes.iter().zip(&parameters) {
            if &p.name != name || &p.shape != shape {
                return Err(InferError::invalid(format!(
                    "parameter {} {:?} found where {name} {shape:?} was expected",
                    p.name, p.shape
                )));
            }
            if p.data.len() != shape.iter().product::<usize>() {
                return Err(InferError::invalid(format!(
                    "parameter {name} has {} values for shape {shape:?}",
                    p.data.len()
                )));
            }
            if p.data.iter().any(|v| !v.is_finite()) {
                return Err(InferError::invalid(format!(
                    "parameter {name} holds non-finite values"
                )));
            }
        }
        let members = match &architecture {
            Architecture::Average { members } => {
                let mut rest = parameters.iter();
                members
                    .iter()
                    .enumerate()
                    .map(|(i, member)| {
                        let count = member.parameter_shapes(inputs, outputs)?.len();
                        let prefix = format!("m{i}.");
                        let own = rest
                            .by_ref()
                            .take(count)
                            .map(|p| Parameter {
                                name: p.name.trim_start_matches(&prefix).to_string(),
                                ..p.clone()
                            })
                            .collect();
                        Network::new(member.clone(), inputs, outputs, own)
                    })
                    .collect::<Result<Vec<_>>>()?
            }
            _ => Vec::new(),
        };
        Ok(Network {
            architecture,
            inputs,
            outputs,
            parameters,
            members,
        })
    }

    /// The mean of `members`' outputs, as one network (see [`Architecture::Average`]); an
    /// error unless they have the same inputs and outputs and none is itself an average.
    pub fn average(members: &[Network]) -> Result<Network> {
        let first = members
            .first()
            .ok_or_else(|| InferError::invalid("an average needs members, got none"))?;
        if let Some(m) = members
            .iter()
            .find(|m| (m.inputs, m.outputs) != (first.inputs, first.outputs))
        {
            return Err(InferError::invalid(format!(
                "the members differ in size: {} → {} and {} → {}",
                first.inputs, first.outputs, m.inputs, m.outputs
            )));
        }
        let architecture = Architecture::Average {
            members: members.iter().map(|m| m.architecture.clone()).collect(),
        };
        let parameters = members
            .iter()
            .enumerate()
            .flat_map(|(i, m)| {
                m.parameters.iter().map(move |p| Parameter {
                    name: format!("m{i}.{}", p.name),
                    ..p.clone()
                })
            })
            .collect();
        Network::new(architecture, first.inputs, first.outputs, parameters)
    }

    /// The architecture.
    pub fn architecture(&self) -> &Architecture {
        &self.architecture
    }

    /// The number of input features.
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// The number of outputs.
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// The parameters, in forward order.
    pub fn parameters(&self) -> &[Parameter] {
        &self.parameters
    }

    /// The number of trainable values.
    pub fn parameter_count(&self) -> usize {
        self.parameters.iter().map(|p| p.data.len()).sum()
    }

    /// Weight and bias of dense layer `i` in forward order (`new` checked the layout).
    fn layer(&self, i: usize) -> (&Parameter, &Parameter) {
        (&self.parameters[2 * i], &self.parameters[2 * i + 1])
    }

    /// The number of dense (or convolution) layers.
    fn layer_count(&self) -> usize {
        self.parameters.len() / 2
    }

    /// Outputs for `rows` rows of normalised features (row-major); sigmoid outputs for the
    /// networks, plain linear outputs for `linear`, their mean for `average`. Blocks of rows
    /// run in parallel.
    pub fn forward(&self, x: &[f32]) -> Result<Vec<f32>> {
        if !x.len().is_multiple_of(self.inputs) {
            return Err(InferError::invalid(format!(
                "{} values do not form rows of {} features",
                x.len(),
                self.inputs
            )));
        }
        let rows = x.len() / self.inputs;
        let mut out = vec![0.0f32; rows * self.outputs];
        if rows <= BLOCK_ROWS {
            self.forward_block(x, rows, &mut out);
        } else {
            x.par_chunks(BLOCK_ROWS * self.inputs)
                .zip(out.par_chunks_mut(BLOCK_ROWS * self.outputs))
                .for_each(|(xb, ob)| self.forward_block(xb, xb.len() / self.inputs, ob));
        }
        Ok(out)
    }

    fn forward_block(&self, x: &[f32], rows: usize, out: &mut [f32]) {
        match &self.architecture {
            Architecture::Cnn1d(s) => self.forward_cnn(s, x, rows, out),
            Architecture::Mlp(s) => {
                let mut h = x.to_vec();
                let mut width = self.inputs;
                for (i, &units) in s.hidden.iter().enumerate() {
                    let mut next = vec![0.0f32; rows * units];
                    let (w, b) = self.layer(i);
                    dense_into(&h, rows, width, width, w, b, &mut next, true);
                    h = next;
                    width = units;
                }
                let (w, b) = self.layer(self.layer_count() - 1);
                dense_into(&h, rows, width, width, w, b, out, false);
                out.iter_mut().for_each(|v| *v = sigmoid(*v));
            }
            Architecture::Linear { .. } => {
                let (w, b) = self.layer(0);
                dense_into(x, rows, self.inputs, self.inputs, w, b, out, false);
            }
            Architecture::Average { .. } => {
                out[..rows * self.outputs].fill(0.0);
                let mut own = vec![0.0f32; rows * self.outputs];
                let share = 1.0 / self.members.len() as f32;
                for member in &self.members {
                    member.forward_block(x, rows, &mut own);
                    for (o, v) in out.iter_mut().zip(&own) {
                        *o += share * v;
                    }
                }
            }
        }
    }

    fn forward_cnn(&self, s: &CnnSpec, x: &[f32], rows: usize, out: &mut [f32]) {
        // `lengths` succeeded in `new`.
        let [l1, l2, l3] = s.lengths(self.inputs).unwrap_or([1, 1, 1]);
        let (f1, f2) = (s.conv1_filters, s.conv2_filters);
        let (w1, b1) = self.layer(0);
        let (w2, b2) = self.layer(1);
        let mut h1 = vec![0.0f32; l1 * f1];
        let mut h2 = vec![0.0f32; l2 * f2];
        let flat = l3 * f2;
        let mut pooled = vec![0.0f32; rows * flat];
        for (r, p) in pooled.chunks_exact_mut(flat).enumerate() {
            let xr = &x[r * self.inputs..(r + 1) * self.inputs];
            // Windows of the input overlap: row t starts at t, stride 1.
            dense_into(xr, l1, s.conv1_kernel, 1, w1, b1, &mut h1, true);
            dense_into(&h1, l2, s.conv2_kernel * f1, f1, w2, b2, &mut h2, true);
            for (t, pt) in p.chunks_exact_mut(f2).enumerate() {
                let base = t * s.pool * f2;
                pt.copy_from_slice(&h2[base..base + f2]);
                for k in 1..s.pool {
                    let src = &h2[base + k * f2..base + (k + 1) * f2];
                    for (a, &b) in pt.iter_mut().zip(src) {
                        *a = a.max(b);
                    }
                }
            }
        }
        let mut hidden = vec![0.0f32; rows * s.dense];
        let (wd, bd) = self.layer(2);
        dense_into(&pooled, rows, flat, flat, wd, bd, &mut hidden, true);
        let (wo, bo) = self.layer(3);
        dense_into(&hidden, rows, s.dense, s.dense, wo, bo, out, false);
        out.iter_mut().for_each(|v| *v = sigmoid(*v));
    }
}

impl Network {
    /// A network with freshly initialised weights: Glorot-uniform weights (fan-in and
    /// fan-out counted as Keras does for convolutions) and zero biases, from `seed`.
    pub fn init(
        architecture: Architecture,
        inputs: usize,
        outputs: usize,
        seed: u64,
    ) -> Result<Network> {
        use rand::{Rng, SeedableRng};
        architecture.validate()?;
        if let Architecture::Average { .. } = architecture {
            return Err(InferError::invalid(
                "an average is made of trained networks (spdcam average), not initialised",
            ));
        }
        let shapes = architecture.parameter_shapes(inputs, outputs)?;
        let mut rng = rand::rngs::SmallRng::seed_from_u64(seed);
        let mut parameters = Vec::with_capacity(shapes.len());
        for (index, (name, shape)) in shapes.into_iter().enumerate() {
            let count: usize = shape.iter().product();
            let data = if shape.len() == 2 {
                let (fan_in, mut fan_out) = (shape[0], shape[1]);
                if let Architecture::Cnn1d(s) = &architecture {
                    match index / 2 {
                        0 => fan_out *= s.conv1_kernel,
                        1 => fan_out *= s.conv2_kernel,
                        _ => {}
                    }
                }
                let limit = (6.0 / (fan_in + fan_out) as f64).sqrt() as f32;
                (0..count)
                    .map(|_| rng.random_range(-limit..limit))
                    .collect()
            } else {
                vec![0.0; count]
            };
            parameters.push(Parameter { name, shape, data });
        }
        Network::new(architecture, inputs, outputs, parameters)
    }

    /// The same network with a freshly initialised output layer of `outputs` units (for
    /// transfer learning): every other layer keeps its weights.
    pub fn with_new_output(&self, outputs: usize, seed: u64) -> Result<Network> {
        let fresh = Network::init(self.architecture.clone(), self.inputs, outputs, seed)?;
        let n = self.parameters.len();
        let mut parameters = self.parameters[..n - 2].to_vec();
        parameters.extend_from_slice(&fresh.parameters[n - 2..]);
        Network::new(self.architecture.clone(), self.inputs, outputs, parameters)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A direct, loop-by-loop forward pass of the 1D CNN, to check the matrix version.
    fn cnn_reference(net: &Network, s: &CnnSpec, x: &[f32]) -> Vec<f32> {
        let p = net.parameters();
        let n = net.inputs();
        let [l1, l2, l3] = s.lengths(n).unwrap();
        let (f1, f2) = (s.conv1_filters, s.conv2_filters);
        let mut h1 = vec![0.0f32; l1 * f1];
        for t in 0..l1 {
            for c in 0..f1 {
                let mut v = p[1].data[c];
                for k in 0..s.conv1_kernel {
                    v += x[t + k] * p[0].data[k * f1 + c];
                }
                h1[t * f1 + c] = v.max(0.0);
            }
        }
        let mut h2 = vec![0.0f32; l2 * f2];
        for t in 0..l2 {
            for c in 0..f2 {
                let mut v = p[3].data[c];
                for k in 0..s.conv2_kernel {
                    for ci in 0..f1 {
                        v += h1[(t + k) * f1 + ci] * p[2].data[(k * f1 + ci) * f2 + c];
                    }
                }
                h2[t * f2 + c] = v.max(0.0);
            }
        }
        let mut flat = vec![f32::NEG_INFINITY; l3 * f2];
        for t in 0..l3 {
            for c in 0..f2 {
                for k in 0..s.pool {
                    flat[t * f2 + c] = flat[t * f2 + c].max(h2[(t * s.pool + k) * f2 + c]);
                }
            }
        }
        let dense = |x: &[f32], w: &Parameter, b: &Parameter| -> Vec<f32> {
            let o = b.data.len();
            (0..o)
                .map(|j| {
                    b.data[j]
                        + x.iter()
                            .enumerate()
                            .map(|(i, v)| v * w.data[i * o + j])
                            .sum::<f32>()
                })
                .collect()
        };
        let h3: Vec<f32> = dense(&flat, &p[4], &p[5])
            .into_iter()
            .map(|v| v.max(0.0))
            .collect();
        dense(&h3, &p[6], &p[7]).into_iter().map(sigmoid).collect()
    }

    #[test]
    fn cnn_forward_matches_a_direct_computation() {
        let s = CnnSpec::thesis();
        let net = Network::init(Architecture::Cnn1d(s.clone()), 72, 5, 3).unwrap();
        let rows = 300; // more than one block
        let x: Vec<f32> = (0..rows * 72)
            .map(|i| ((i * 37 % 101) as f32) / 101.0)
            .collect();
        let y = net.forward(&x).unwrap();
        for r in [0, 17, 299] {
            let expected = cnn_reference(&net, &s, &x[r * 72..(r + 1) * 72]);
            for (a, b) in y[r * 5..(r + 1) * 5].iter().zip(&expected) {
                assert!((a - b).abs() < 1e-5, "row {r}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn wrong_parameters_are_an_error() {
        let net = Network::init(Architecture::Mlp(MlpSpec::thesis()), 72, 5, 1).unwrap();
        let mut params = net.parameters().to_vec();
        params[0].shape = vec![71, 32];
        assert!(Network::new(net.architecture().clone(), 72, 5, params).is_err());
        let mut params = net.parameters().to_vec();
        params[3].data[0] = f32::NAN;
        assert!(Network::new(net.architecture().clone(), 72, 5, params).is_err());
        assert!(net.forward(&[0.0; 71]).is_err());
        // The CNN needs enough inputs for its kernels.
        assert!(Network::init(Architecture::Cnn1d(CnnSpec::thesis()), 10, 5, 1).is_err());
    }

    #[test]
    fn an_average_outputs_the_mean_of_its_members() {
        let mlp = Network::init(
            Architecture::Mlp(MlpSpec {
                hidden: vec![8, 4],
                dropout: 0.0,
            }),
            6,
            3,
            1,
        )
        .unwrap();
        // A linear member with known weights: output j = j + 0.5 · x₀.
        let linear = Network::new(
            Architecture::Linear { ridge: 1e-3 },
            6,
            3,
            vec![
                Parameter {
                    name: "output.weight".into(),
                    shape: vec![6, 3],
                    data: (0..18).map(|i| if i < 3 { 0.5 } else { 0.0 }).collect(),
                },
                Parameter {
                    name: "output.bias".into(),
                    shape: vec![3],
                    data: vec![0.0, 1.0, 2.0],
                },
            ],
        )
        .unwrap();
        let average = Network::average(&[mlp.clone(), linear.clone()]).unwrap();
        assert_eq!(average.architecture().label(), "average of mlp and linear");
        assert_eq!(average.parameters()[0].name, "m0.hidden0.weight");
        assert_eq!(average.parameters().last().unwrap().name, "m1.output.bias");
        let rows = 300; // more than one block
        let x: Vec<f32> = (0..rows * 6).map(|i| (i % 7) as f32 / 7.0).collect();
        let (a, b, mean) = (
            mlp.forward(&x).unwrap(),
            linear.forward(&x).unwrap(),
            average.forward(&x).unwrap(),
        );
        for r in 0..rows {
            for j in 0..3 {
                let k = r * 3 + j;
                assert_eq!(b[k], j as f32 + 0.5 * x[r * 6]);
                assert!((mean[k] - 0.5 * (a[k] + b[k])).abs() < 1e-6, "{k}");
            }
        }
        // Rebuilt from its stored parameters (as a model file is read), it is the same.
        let again = Network::new(
            average.architecture().clone(),
            6,
            3,
            average.parameters().to_vec(),
        )
        .unwrap();
        assert_eq!(again.forward(&x).unwrap(), mean);
    }

    #[test]
    fn a_bad_average_is_an_error() {
        let mlp = Network::init(Architecture::Mlp(MlpSpec::thesis()), 72, 5, 1).unwrap();
        let other = Network::init(Architecture::Mlp(MlpSpec::thesis()), 72, 4, 1).unwrap();
        assert!(Network::average(&[]).is_err());
        assert!(
            Network::average(&[mlp.clone(), other]).is_err(),
            "sizes differ"
        );
        // One member, or an average inside an average, is not an average.
        assert!(Architecture::Average {
            members: vec![Architecture::Linear { ridge: 0.0 }]
        }
        .validate()
        .is_err());
        let pair = Network::average(&[mlp.clone(), mlp.clone()]).unwrap();
        assert!(Network::average(&[pair.clone(), mlp]).is_err());
        assert!(Network::init(pair.architecture().clone(), 72, 5, 1).is_err());
    }
}
