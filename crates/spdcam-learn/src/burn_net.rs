//! The networks as burn modules, for training. Their parameters have the layouts of
//! [`spdcam_infer::network`], so weights move between the two with plain copies.
//!
//! The convolutions are written as dense layers over windows (im2col), which flex runs as one
//! large matrix product per layer; the max pooling is an element-wise maximum of the
//! interleaved positions (no scatter in its backward pass); dropout multiplies by masks drawn
//! with a fast seeded generator (burn's own Bernoulli sampling was ~10 % of a step).

use crate::error::{LearnError, Result};
use burn::module::{Module, Param, ParamId};
use burn::nn::Linear;
use burn::optim::GradientsParams;
use burn::tensor::activation::{relu, sigmoid};
use burn::tensor::{Device, Tensor, TensorData};
use rand::Rng;
use spdcam_infer::network::{Architecture, CnnSpec, Network, Parameter};

/// The trainable layers: dense (or convolution-as-dense) layers in forward order.
#[derive(Module, Debug)]
pub(crate) struct BurnNet {
    layers: Vec<Linear>,
}

/// A batch of inputs prepared for a network: for the CNN, the windows of the first
/// convolution (`[rows, l1, kernel]`); for the MLP, the rows (`[rows, features]`).
pub(crate) enum Input {
    /// Rank-3 windows.
    Windows(Tensor<3>),
    /// Rank-2 rows.
    Rows(Tensor<2>),
}

fn tensor_of(p: &Parameter, device: &Device) -> Result<Param<Tensor<2>>> {
    match p.shape.as_slice() {
        [i, o] => Ok(Param::from_tensor(Tensor::from_data(
            TensorData::new(p.data.clone(), [*i, *o]),
            device,
        ))),
        s => Err(LearnError::invalid(format!(
            "parameter {} has shape {s:?}, a weight must be 2-D",
            p.name
        ))),
    }
}

impl BurnNet {
    /// A burn module holding the weights of `network` on `device`.
    pub(crate) fn from_network(network: &Network, device: &Device) -> Result<BurnNet> {
        match network.architecture() {
            Architecture::Linear { .. } => {
                return Err(LearnError::invalid(
                    "the linear model is fitted in closed form, not trained by gradient",
                ))
            }
            Architecture::Average { .. } => {
                return Err(LearnError::invalid(
                    "an average is made of trained models, not trained by gradient",
                ))
            }
            _ => {}
        }
        let mut layers = Vec::new();
        for pair in network.parameters().chunks_exact(2) {
            let weight = tensor_of(&pair[0], device)?;
            let bias = Tensor::<1>::from_data(
                TensorData::new(pair[1].data.clone(), [pair[1].data.len()]),
                device,
            );
            layers.push(Linear {
                weight,
                bias: Some(Param::from_tensor(bias)),
            });
        }
        Ok(BurnNet { layers })
    }

    /// The weights as plain parameters, named and shaped like `template`'s.
    pub(crate) fn to_network(&self, template: &Network) -> Result<Network> {
        let mut parameters = Vec::with_capacity(template.parameters().len());
        for (layer, pair) in self
            .layers
            .iter()
            .zip(template.parameters().chunks_exact(2))
        {
            let weight = to_vec(layer.weight.val().into_data())?;
            let bias = match &layer.bias {
                Some(b) => to_vec(b.val().into_data())?,
                None => vec![0.0; pair[1].data.len()],
            };
            parameters.push(Parameter {
                name: pair[0].name.clone(),
                shape: pair[0].shape.clone(),
                data: weight,
            });
            parameters.push(Parameter {
                name: pair[1].name.clone(),
                shape: pair[1].shape.clone(),
                data: bias,
            });
        }
        Ok(Network::new(
            template.architecture().clone(),
            template.inputs(),
            template.outputs(),
            parameters,
        )?)
    }

    /// Replaces the freezable layers (all but the output layer) by frozen copies.
    pub(crate) fn freeze_features(mut self) -> BurnNet {
        let last = self.layers.len().saturating_sub(1);
        self.layers = self
            .layers
            .into_iter()
            .enumerate()
            .map(|(i, l)| if i < last { l.no_grad() } else { l })
            .collect();
        self
    }

    /// A copy of the network whose parameters are new leaves of the autodiff graph (same
    /// values, same parameter ids): a step on it builds its own graph, which burn keeps
    /// under its own lock, so copies run forward and backward passes on separate threads at
    /// once. Their gradients are keyed by the original parameter ids.
    pub(crate) fn replica(&self) -> BurnNet {
        let detached = |p: &Param<Tensor<2>>| Param::initialized(p.id, p.val().detach());
        let layers = self
            .layers
            .iter()
            .map(|l| Linear {
                weight: detached(&l.weight),
                bias: l
                    .bias
                    .as_ref()
                    .map(|b| Param::initialized(b.id, b.val().detach())),
            })
            .collect();
        BurnNet { layers }
    }

    /// The sum of the gradients of several parts of one batch (computed on replicas).
    pub(crate) fn sum_gradients(&self, parts: Vec<GradientsParams>) -> GradientsParams {
        let mut parts = parts.into_iter();
        let Some(mut total) = parts.next() else {
            return GradientsParams::new();
        };
        for mut part in parts {
            for layer in &self.layers {
                add_gradient::<2>(&mut total, &mut part, layer.weight.id);
                if let Some(b) = &layer.bias {
                    add_gradient::<1>(&mut total, &mut part, b.id);
                }
            }
        }
        total
    }

    /// The outputs (after the sigmoid) for a prepared batch, with the dropout masks of
    /// [`dropout_masks`] (none: no dropout).
    pub(crate) fn forward(
        &self,
        architecture: &Architecture,
        input: Input,
        masks: Vec<Tensor<2>>,
    ) -> Result<Tensor<2>> {
        let mut masks = masks.into_iter();
        let mut drop = |h: Tensor<2>| match masks.next() {
            Some(m) => h * m,
            None => h,
        };
        match (architecture, input) {
            (Architecture::Cnn1d(s), Input::Windows(x)) => Ok(self.forward_cnn(s, x, &mut drop)),
            (Architecture::Mlp(_), Input::Rows(x)) => {
                let last = self.layers.len() - 1;
                let mut h = x;
                for layer in &self.layers[..last] {
                    h = drop(relu(layer.forward(h)));
                }
                Ok(sigmoid(self.layers[last].forward(h)))
            }
            _ => Err(LearnError::invalid(
                "the batch was prepared for another architecture",
            )),
        }
    }

    fn forward_cnn(
        &self,
        s: &CnnSpec,
        x: Tensor<3>,
        drop: &mut dyn FnMut(Tensor<2>) -> Tensor<2>,
    ) -> Tensor<2> {
        let [rows, l1, k1] = x.dims();
        let l2 = l1 + 1 - s.conv2_kernel;
        let l3 = l2 / s.pool;
        let (f1, f2) = (s.conv1_filters, s.conv2_filters);
        // Every product is a rank-2 matmul over all positions of the batch at once.
        let h1 = relu(self.layers[0].forward(x.reshape([rows * l1, k1]))).reshape([rows, l1, f1]);
        // Windows of the second convolution, position-major: [rows, l2, kernel · filters].
        let windows: Vec<Tensor<3>> = (0..s.conv2_kernel)
            .map(|t| h1.clone().narrow(1, t, l2))
            .collect();
        let windows = Tensor::cat(windows, 2).reshape([rows * l2, s.conv2_kernel * f1]);
        let h2 = relu(self.layers[1].forward(windows)).reshape([rows, l2, f2]);
        // Max pooling: positions t·pool + j lie side by side in [rows, l3, pool · f2].
        let runs = h2
            .narrow(1, 0, l3 * s.pool)
            .reshape([rows, l3, s.pool * f2]);
        let mut pooled = runs.clone().narrow(2, 0, f2);
        for j in 1..s.pool {
            pooled = pooled.max_pair(runs.clone().narrow(2, j * f2, f2));
        }
        let pooled = pooled.reshape([rows, l3 * f2]);
        let h3 = relu(self.layers[2].forward(drop(pooled)));
        sigmoid(self.layers[3].forward(h3))
    }
}

/// Dropout masks for one batch (`0` or `1 / (1 − p)` per value), one per dropout site of
/// the architecture; none when its dropout probability is 0.
pub(crate) fn dropout_masks(
    architecture: &Architecture,
    rows: usize,
    features: usize,
    rng: &mut rand::rngs::SmallRng,
    device: &Device,
) -> Result<Vec<Tensor<2>>> {
    let (p, widths) = match architecture {
        Architecture::Cnn1d(s) => {
            let [_, _, l3] = s.lengths(features)?;
            (s.dropout, vec![l3 * s.conv2_filters])
        }
        Architecture::Mlp(s) => (s.dropout, s.hidden.clone()),
        Architecture::Linear { .. } | Architecture::Average { .. } => (0.0, Vec::new()),
    };
    if p <= 0.0 {
        return Ok(Vec::new());
    }
    let keep = 1.0 - p;
    let scale = (1.0 / keep) as f32;
    let threshold = (keep * f64::from(u32::MAX)) as u32;
    Ok(widths
        .into_iter()
        .map(|w| {
            let mask: Vec<f32> = (0..rows * w)
                .map(|_| {
                    if rng.random::<u32>() < threshold {
                        scale
                    } else {
                        0.0
                    }
                })
                .collect();
            Tensor::from_data(TensorData::new(mask, [rows, w]), device)
        })
        .collect())
}

/// Adds `part`'s gradient of parameter `id` to `total`'s (frozen parameters have none).
fn add_gradient<const D: usize>(
    total: &mut GradientsParams,
    part: &mut GradientsParams,
    id: ParamId,
) {
    if let Some(g) = part.remove::<D>(id) {
        let sum = match total.remove::<D>(id) {
            Some(t) => t + g,
            None => g,
        };
        total.register(id, sum);
    }
}

fn to_vec(data: TensorData) -> Result<Vec<f32>> {
    data.try_to_vec_as::<f32>()
        .map_err(|e| LearnError::Numerical(format!("reading weights back from burn: {e:?}")))
}

/// Prepares rows of normalised features (`[rows, features]`, row-major) for `architecture`.
pub(crate) fn prepare(
    architecture: &Architecture,
    x: &[f32],
    rows: usize,
    features: usize,
    device: &Device,
) -> Result<Input> {
    match architecture {
        Architecture::Cnn1d(s) => {
            let [l1, _, _] = s.lengths(features)?;
            let k = s.conv1_kernel;
            let mut windows = Vec::with_capacity(rows * l1 * k);
            for row in x.chunks_exact(features) {
                for t in 0..l1 {
                    windows.extend_from_slice(&row[t..t + k]);
                }
            }
            Ok(Input::Windows(Tensor::from_data(
                TensorData::new(windows, [rows, l1, k]),
                device,
            )))
        }
        Architecture::Mlp(_) => Ok(Input::Rows(Tensor::from_data(
            TensorData::new(x.to_vec(), [rows, features]),
            device,
        ))),
        Architecture::Linear { .. } | Architecture::Average { .. } => Err(LearnError::invalid(
            "a linear model or an average is not trained by gradient",
        )),
    }
}
