//! NI scaling of TDMS channels: the `NI_Scale[i]_*` properties that LabVIEW and DAQmx
//! write beside values stored unscaled (`NI_Scaling_Status` = `"unscaled"`, the default),
//! as npTDMS applies them (`nptdms/scaling.py`).
//!
//! A channel's scales come from its own properties, else its group's, else the file's:
//! the first of these that defines scales and is not marked `"scaled"`. There are
//! `NI_Number_Of_Scales` of them (or one more than the largest `i` of an
//! `NI_Scale[i]_Scale_Type`); the channel's values are those of the last, each scale
//! reading its input (`NI_Scale[i]_<Type>_Input_Source`: an earlier scale, or
//! `0xFFFFFFFF` for the stored values, the default):
//!
//! ```text
//! Linear       y = x slope + y_intercept                       (NI_Scale[i]_Linear_Slope, _Y_Intercept)
//! Polynomial   y = c0 + x (c1 + x (c2 + ...))                  (NI_Scale[i]_Polynomial_Coefficients[j],
//!                                                               _Coefficients_Size, default 4)
//! AdvancedAPI  y = x
//! (no type)    y = the values of DAQmx scaler i                (DAQmx raw data, see the parent module)
//! ```
//!
//! The arithmetic is numpy's, operation for operation (Horner's rule from the highest
//! coefficient for a polynomial, as `numpy.polynomial.polynomial.polyval`), so the values
//! are bit for bit npTDMS's. Any other scale type (thermocouple, RTD, strain, table,
//! thermistor, add, subtract) is refused rather than returned unscaled, as is a scale whose
//! input is not an earlier scale (which could loop) or whose properties are missing.

use std::collections::HashMap;

/// The input source meaning "the stored values".
pub(super) const RAW: u32 = 0xFFFF_FFFF;

/// Scales a channel may define, at most (a bound on what a hostile count allocates).
const MAX_SCALES: u64 = 4096;

/// A kept property value.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Value {
    Number(f64),
    Text(String),
}

/// The scaling properties of one object (names starting `NI_Scal`, and
/// `NI_Number_Of_Scales`), each with the byte offset of its property in the file.
#[derive(Debug, Clone, Default)]
pub(super) struct Props(HashMap<String, (Value, u64)>);

impl Props {
    /// Whether the reader keeps a property of this name.
    pub(super) fn wanted(name: &str) -> bool {
        name.starts_with("NI_Scal") || name == "NI_Number_Of_Scales"
    }

    /// Keep (or replace, as a later segment may) property `name` found at `offset`.
    pub(super) fn set(&mut self, name: &str, value: Value, offset: u64) {
        self.0.insert(name.to_string(), (value, offset));
    }

    fn get(&self, name: &str) -> Option<&(Value, u64)> {
        self.0.get(name)
    }

    /// Any property at all (its offset), to locate an error about the scales as a whole.
    fn any_offset(&self) -> u64 {
        self.0.values().map(|(_, o)| *o).min().unwrap_or(0)
    }
}

/// Why a channel's scaling cannot be applied: the property (and its offset) at fault.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Refusal {
    pub offset: u64,
    pub what: String,
    pub found: String,
    pub allowed: String,
}

fn refuse(offset: u64, what: String, found: impl ToString, allowed: &str) -> Refusal {
    Refusal {
        offset,
        what,
        found: found.to_string(),
        allowed: allowed.to_string(),
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Scale {
    Linear {
        slope: f64,
        intercept: f64,
        input: u32,
    },
    Polynomial {
        coefficients: Vec<f64>,
        input: u32,
    },
    Identity {
        input: u32,
    },
    /// The values of DAQmx scaler `id`.
    Scaler {
        id: u32,
    },
}

/// The scales of a channel, the last giving its values.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Scaling {
    scales: Vec<Scale>,
    /// Where they are defined (to locate an error in applying them).
    offset: u64,
}

/// The scaling of a channel with properties `levels` = [channel, group, file] (module doc);
/// `None` when no level defines one.
pub(super) fn scaling(levels: [&Props; 3]) -> Result<Option<Scaling>, Refusal> {
    for p in levels {
        if let Some(s) = level(p)? {
            return Ok(Some(s));
        }
    }
    Ok(None)
}

fn number(p: &Props, name: &str) -> Result<Option<f64>, Refusal> {
    match p.get(name) {
        None => Ok(None),
        Some((Value::Number(v), _)) => Ok(Some(*v)),
        Some((Value::Text(t), at)) => Err(refuse(
            *at,
            format!("TDMS property {name}"),
            format!("the string {t:?}"),
            "a number",
        )),
    }
}

fn required(p: &Props, name: &str) -> Result<f64, Refusal> {
    number(p, name)?.ok_or_else(|| {
        refuse(
            p.any_offset(),
            format!("TDMS property {name}"),
            "missing",
            "present: the scale it belongs to needs it",
        )
    })
}

/// A count or index property: a whole number in `0..=limit`.
fn whole(p: &Props, name: &str, limit: u64) -> Result<Option<u64>, Refusal> {
    let Some(v) = number(p, name)? else {
        return Ok(None);
    };
    if v >= 0.0 && v <= limit as f64 && v.fract() == 0.0 {
        return Ok(Some(v as u64));
    }
    let at = p.get(name).map_or(0, |(_, o)| *o);
    Err(refuse(
        at,
        format!("TDMS property {name}"),
        v,
        &format!("a whole number from 0 to {limit}"),
    ))
}

fn level(p: &Props) -> Result<Option<Scaling>, Refusal> {
    let n = match whole(p, "NI_Number_Of_Scales", MAX_SCALES)? {
        Some(n) => n,
        None => {
            p.0.keys()
                .filter_map(|k| {
                    k.strip_prefix("NI_Scale[")?
                        .strip_suffix("]_Scale_Type")?
                        .parse::<u64>()
                        .ok()
                })
                .max()
                .map_or(0, |i| i + 1)
        }
    };
    if n == 0 {
        return Ok(None);
    }
    if n > MAX_SCALES {
        return Err(refuse(
            p.any_offset(),
            "TDMS scale count".into(),
            n,
            &format!("at most {MAX_SCALES}"),
        ));
    }
    match p.get("NI_Scaling_Status") {
        Some((Value::Text(s), _)) if s == "scaled" => return Ok(None),
        _ => {}
    }
    let mut scales = Vec::with_capacity(n as usize);
    for i in 0..n {
        let key = |rest: &str| format!("NI_Scale[{i}]_{rest}");
        let input = |ty: &str| -> Result<u32, Refusal> {
            let name = key(&format!("{ty}_Input_Source"));
            Ok(whole(p, &name, u64::from(RAW))?.map_or(RAW, |v| v as u32))
        };
        let scale = match p.get(&key("Scale_Type")) {
            None => Scale::Scaler { id: i as u32 },
            Some((Value::Text(t), at)) => match t.as_str() {
                "Linear" => Scale::Linear {
                    slope: required(p, &key("Linear_Slope"))?,
                    intercept: required(p, &key("Linear_Y_Intercept"))?,
                    input: input("Linear")?,
                },
                "Polynomial" => {
                    let size =
                        whole(p, &key("Polynomial_Coefficients_Size"), MAX_SCALES)?.unwrap_or(4);
                    let coefficients = (0..size)
                        .map(|j| required(p, &key(&format!("Polynomial_Coefficients[{j}]"))))
                        .collect::<Result<Vec<_>, _>>()?;
                    Scale::Polynomial {
                        coefficients,
                        input: input("Polynomial")?,
                    }
                }
                "AdvancedAPI" => Scale::Identity {
                    input: input("AdvancedAPI")?,
                },
                other => {
                    return Err(refuse(
                        *at,
                        format!("TDMS property {}", key("Scale_Type")),
                        format!("{other:?}"),
                        "Linear, Polynomial or AdvancedAPI (the scales rotorid applies; \
                         convert the channel to its scaled values in LabVIEW or npTDMS first)",
                    ))
                }
            },
            Some((Value::Number(v), at)) => {
                return Err(refuse(
                    *at,
                    format!("TDMS property {}", key("Scale_Type")),
                    v,
                    "a string naming the scale type",
                ))
            }
        };
        // An input must come before the scale that reads it, so evaluation ends.
        let source = match &scale {
            Scale::Linear { input, .. }
            | Scale::Polynomial { input, .. }
            | Scale::Identity { input } => Some(*input),
            Scale::Scaler { .. } => None,
        };
        if let Some(s) = source.filter(|&s| s != RAW && u64::from(s) >= i) {
            let ty = match &scale {
                Scale::Linear { .. } => "Linear",
                Scale::Polynomial { .. } => "Polynomial",
                _ => "AdvancedAPI",
            };
            let name = key(&format!("{ty}_Input_Source"));
            let at = p.get(&name).map_or(0, |(_, o)| *o);
            let allowed = match i {
                0 => "4294967295 (the stored values): scale 0 has no earlier scale".to_string(),
                _ => format!(
                    "an earlier scale (0 to {}) or 4294967295 (the stored values)",
                    i - 1
                ),
            };
            return Err(refuse(at, format!("TDMS property {name}"), s, &allowed));
        }
        scales.push(scale);
    }
    Ok(Some(Scaling {
        scales,
        offset: p.any_offset(),
    }))
}

/// What a channel's last scale reads, through the chain of its inputs: the stored values
/// or a DAQmx scaler's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Input {
    /// The stored values.
    Stored,
    /// The values of DAQmx scaler `id`.
    Scaler(u32),
}

/// A [`Scaling`] resolved: what it reads, and the scales applied to that, in order.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Chain {
    pub input: Input,
    /// The scales from the one reading `input` up to the last.
    order: Vec<usize>,
    /// The scale that reads `input` (to name it in an error).
    reader: usize,
    scales: Vec<Scale>,
    offset: u64,
}

impl Scaling {
    /// The chain from the last scale down to what it reads (inputs come before the
    /// scales that read them, so it ends).
    pub(super) fn chain(&self) -> Chain {
        let mut order = Vec::new();
        let mut i = self.scales.len() - 1;
        let input = loop {
            let source = match &self.scales[i] {
                Scale::Linear { input, .. }
                | Scale::Polynomial { input, .. }
                | Scale::Identity { input } => *input,
                Scale::Scaler { id } => break Input::Scaler(*id),
            };
            order.push(i);
            if source == RAW {
                break Input::Stored;
            }
            i = source as usize;
        };
        order.reverse();
        Chain {
            input,
            order,
            reader: i,
            scales: self.scales.clone(),
            offset: self.offset,
        }
    }

    /// The channel's values: the last scale applied, through its inputs, to `raw` (the
    /// stored values; `None` for a DAQmx raw channel, which has only its scalers' values)
    /// or to `scaler(id)`. A chain of scales reads one of these once, and each scale
    /// works in place, so memory holds one channel's values.
    #[cfg(test)]
    pub(super) fn apply(
        &self,
        raw: Option<Vec<f64>>,
        scaler: &mut dyn FnMut(u32) -> Option<Vec<f64>>,
    ) -> Result<Vec<f64>, Refusal> {
        let chain = self.chain();
        let mut v = match chain.input {
            Input::Scaler(id) => scaler(id),
            Input::Stored => raw,
        }
        .ok_or_else(|| chain.missing())?;
        chain.apply_in_place(&mut v);
        Ok(v)
    }
}

impl Chain {
    /// The refusal when the channel has no values of the chain's input (no such DAQmx
    /// scaler; stored values asked of a DAQmx raw channel).
    pub(super) fn missing(&self) -> Refusal {
        let i = self.reader;
        match self.input {
            Input::Scaler(id) => refuse(
                self.offset,
                format!("TDMS scale {i}"),
                format!("the values of DAQmx scaler {id}, which the channel does not have"),
                "a scaler of the channel's DAQmx raw data index",
            ),
            Input::Stored => refuse(
                self.offset,
                format!("TDMS scale {i}"),
                "reading the stored values of a DAQmx raw channel",
                "a DAQmx scaler's values (a scale without a type names them)",
            ),
        }
    }

    /// The scales applied to the input's values `v`, in place, value by value (so a block
    /// of the values scales as the whole channel does, bit for bit).
    pub(super) fn apply_in_place(&self, v: &mut [f64]) {
        for &i in &self.order {
            match &self.scales[i] {
                Scale::Linear {
                    slope, intercept, ..
                } => {
                    for x in v.iter_mut() {
                        *x = *x * slope + intercept;
                    }
                }
                Scale::Polynomial { coefficients, .. } => match coefficients.split_last() {
                    None => v.iter_mut().for_each(|x| *x = 0.0),
                    Some((&last, rest)) => {
                        for x in v.iter_mut() {
                            // numpy's polyval: c[-1] + x * 0, then c[k] + acc * x
                            let mut acc = last + *x * 0.0;
                            for &c in rest.iter().rev() {
                                acc = c + acc * *x;
                            }
                            *x = acc;
                        }
                    }
                },
                Scale::Identity { .. } | Scale::Scaler { .. } => {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    //! The cases of npTDMS's `nptdms/test/test_scaling.py`, with its expected values.
    use super::*;

    fn props(entries: &[(&str, Value)]) -> Props {
        let mut p = Props::default();
        for (k, (name, v)) in entries.iter().enumerate() {
            p.set(name, v.clone(), 100 + k as u64);
        }
        p
    }

    fn n(v: f64) -> Value {
        Value::Number(v)
    }

    fn s(v: &str) -> Value {
        Value::Text(v.to_string())
    }

    fn scaled(p: &Props, data: &[f64]) -> Vec<f64> {
        let none = Props::default();
        scaling([p, &none, &none])
            .unwrap()
            .unwrap()
            .apply(Some(data.to_vec()), &mut |_| None)
            .unwrap()
    }

    #[test]
    fn linear() {
        let p = props(&[
            ("NI_Scaling_Status", s("unscaled")),
            ("NI_Number_Of_Scales", n(1.0)),
            ("NI_Scale[0]_Scale_Type", s("Linear")),
            ("NI_Scale[0]_Linear_Slope", n(2.0)),
            ("NI_Scale[0]_Linear_Y_Intercept", n(10.0)),
        ]);
        assert_eq!(scaled(&p, &[1.0, 2.0, 3.0]), [12.0, 14.0, 16.0]);
    }

    #[test]
    fn polynomial_with_4_3_and_no_coefficients() {
        let mut p = props(&[
            ("NI_Number_Of_Scales", n(1.0)),
            ("NI_Scale[0]_Scale_Type", s("Polynomial")),
            ("NI_Scale[0]_Polynomial_Coefficients[0]", n(10.0)),
            ("NI_Scale[0]_Polynomial_Coefficients[1]", n(1.0)),
            ("NI_Scale[0]_Polynomial_Coefficients[2]", n(2.0)),
            ("NI_Scale[0]_Polynomial_Coefficients[3]", n(3.0)),
        ]);
        assert_eq!(scaled(&p, &[1.0, 2.0, 3.0]), [16.0, 44.0, 112.0]);
        p.set("NI_Scale[0]_Polynomial_Coefficients_Size", n(3.0), 200);
        assert_eq!(scaled(&p, &[1.0, 2.0, 3.0]), [13.0, 20.0, 31.0]);
        p.set("NI_Scale[0]_Polynomial_Coefficients_Size", n(0.0), 200);
        assert_eq!(scaled(&p, &[1.0, 2.0, 3.0]), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn polynomial_is_horner_from_the_highest_coefficient_bit_for_bit() {
        // numpy's polyval: c3, then c2 + x c3, c1 + x (..), c0 + x (..)
        let c = [0.1, -3.7e-4, 2.2e-9, 1.3e-13];
        let p = props(&[
            ("NI_Scale[0]_Scale_Type", s("Polynomial")),
            ("NI_Scale[0]_Polynomial_Coefficients[0]", n(c[0])),
            ("NI_Scale[0]_Polynomial_Coefficients[1]", n(c[1])),
            ("NI_Scale[0]_Polynomial_Coefficients[2]", n(c[2])),
            ("NI_Scale[0]_Polynomial_Coefficients[3]", n(c[3])),
        ]);
        let x = [-32768.0, -1.0, 0.0, 12345.0, 8_388_607.0];
        let want: Vec<f64> = x
            .iter()
            .map(|&x| c[0] + (c[1] + (c[2] + c[3] * x) * x) * x)
            .collect();
        let got = scaled(&p, &x);
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g.to_bits(), w.to_bits());
        }
    }

    #[test]
    fn scales_chain_through_their_input_sources() {
        let chain = |inputs: [f64; 3]| {
            props(&[
                ("NI_Number_Of_Scales", n(3.0)),
                ("NI_Scaling_Status", s("unscaled")),
                ("NI_Scale[0]_Scale_Type", s("Linear")),
                ("NI_Scale[0]_Linear_Slope", n(1.0)),
                ("NI_Scale[0]_Linear_Y_Intercept", n(1.0)),
                ("NI_Scale[0]_Linear_Input_Source", n(inputs[0])),
                ("NI_Scale[1]_Scale_Type", s("Linear")),
                ("NI_Scale[1]_Linear_Slope", n(2.0)),
                ("NI_Scale[1]_Linear_Y_Intercept", n(2.0)),
                ("NI_Scale[1]_Linear_Input_Source", n(inputs[1])),
                ("NI_Scale[2]_Scale_Type", s("Linear")),
                ("NI_Scale[2]_Linear_Slope", n(3.0)),
                ("NI_Scale[2]_Linear_Y_Intercept", n(3.0)),
                ("NI_Scale[2]_Linear_Input_Source", n(inputs[2])),
            ])
        };
        let raw = f64::from(RAW);
        assert_eq!(
            scaled(&chain([raw, 0.0, 1.0]), &[1.0, 2.0, 3.0]),
            [21.0, 27.0, 33.0]
        );
        // only the last applies when every scale reads the stored values
        assert_eq!(
            scaled(&chain([raw, raw, raw]), &[1.0, 2.0, 3.0]),
            [6.0, 9.0, 12.0]
        );
        // an input that is not an earlier scale could loop: refused, naming the property
        let none = Props::default();
        let e = scaling([&chain([raw, 2.0, 1.0]), &none, &none]).unwrap_err();
        assert_eq!(e.what, "TDMS property NI_Scale[1]_Linear_Input_Source");
        assert_eq!(e.offset, 109);
    }

    #[test]
    fn a_chain_as_long_as_allowed_is_applied_without_recursion() {
        let count = MAX_SCALES as usize;
        let mut p = Props::default();
        p.set("NI_Number_Of_Scales", n(count as f64), 0);
        for i in 0..count {
            p.set(&format!("NI_Scale[{i}]_Scale_Type"), s("Linear"), 1);
            p.set(&format!("NI_Scale[{i}]_Linear_Slope"), n(1.0), 1);
            p.set(&format!("NI_Scale[{i}]_Linear_Y_Intercept"), n(1.0), 1);
            let input = if i == 0 {
                f64::from(RAW)
            } else {
                (i - 1) as f64
            };
            p.set(&format!("NI_Scale[{i}]_Linear_Input_Source"), n(input), 1);
        }
        let k = count as f64;
        assert_eq!(scaled(&p, &[0.5, -7.0]), [0.5 + k, -7.0 + k]);
    }

    #[test]
    fn the_channel_then_its_group_then_the_file_and_scaled_means_none() {
        let lin = props(&[
            ("NI_Number_Of_Scales", n(1.0)),
            ("NI_Scale[0]_Scale_Type", s("Linear")),
            ("NI_Scale[0]_Linear_Slope", n(2.0)),
            ("NI_Scale[0]_Linear_Y_Intercept", n(10.0)),
        ]);
        let none = Props::default();
        for levels in [[&none, &lin, &none], [&none, &none, &lin]] {
            let s = scaling(levels).unwrap().unwrap();
            assert_eq!(
                s.apply(Some(vec![1.0, 2.0, 3.0]), &mut |_| None).unwrap(),
                [12.0, 14.0, 16.0]
            );
        }
        let mut done = lin.clone();
        done.set("NI_Scaling_Status", s("scaled"), 300);
        assert_eq!(scaling([&done, &none, &none]).unwrap(), None);
        assert_eq!(scaling([&none, &none, &none]).unwrap(), None);
    }

    #[test]
    fn advanced_api_is_the_identity_and_other_types_are_refused() {
        let p = props(&[
            ("NI_Number_Of_Scales", n(1.0)),
            ("NI_Scale[0]_Scale_Type", s("AdvancedAPI")),
        ]);
        assert_eq!(scaled(&p, &[1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
        let p = props(&[
            ("NI_Number_Of_Scales", n(1.0)),
            ("NI_Scale[0]_Scale_Type", s("Thermocouple")),
        ]);
        let none = Props::default();
        let e = scaling([&p, &none, &none]).unwrap_err();
        assert_eq!(
            (e.what.as_str(), e.found.as_str(), e.offset),
            (
                "TDMS property NI_Scale[0]_Scale_Type",
                "\"Thermocouple\"",
                101
            )
        );
    }

    #[test]
    fn a_scale_without_a_type_is_a_daqmx_scaler_and_missing_values_are_refused() {
        let p = props(&[("NI_Number_Of_Scales", n(1.0))]);
        let none = Props::default();
        let scaler = scaling([&p, &none, &none]).unwrap().unwrap();
        assert_eq!(
            scaler
                .apply(None, &mut |id| (id == 0).then(|| vec![5.0, 6.0]))
                .unwrap(),
            [5.0, 6.0]
        );
        assert!(scaler.apply(None, &mut |_| None).is_err());
        // a linear scale without its intercept
        let p = props(&[
            ("NI_Scale[0]_Scale_Type", s("Linear")),
            ("NI_Scale[0]_Linear_Slope", n(2.0)),
        ]);
        let e = scaling([&p, &none, &none]).unwrap_err();
        assert_eq!(e.what, "TDMS property NI_Scale[0]_Linear_Y_Intercept");
        // a count no file needs
        let p = props(&[("NI_Number_Of_Scales", n(4e9))]);
        assert!(scaling([&p, &none, &none]).is_err());
    }
}
