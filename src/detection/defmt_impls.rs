//! `defmt::Format` for the detection types that hold matrices or ring buffers (feature
//! `defmt`): they print their sizes and summary numbers, not their arrays.

use defmt::{Format, Formatter, write};

use super::{BankState, ChiSquareTest, Detector, ModelBank, Whitener, Window};
use crate::Real;

impl<T: Real + Format, const O: usize> Format for Whitener<T, O> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Whitener {{ O: {=usize}, log_det: {} }}",
            O,
            self.log_det()
        )
    }
}

impl<T: Real + Format, const W: usize> Format for Window<T, W> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Window {{ W: {=usize}, len: {=usize}, sum: {}, skipped: {=u64} }}",
            W,
            self.len(),
            self.sum(),
            self.skipped()
        )
    }
}

impl<T: Real + Format, const W: usize> Format for ChiSquareTest<T, W> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "ChiSquareTest {{ dof: {=u64}, alpha: {}, threshold: {} }}",
            self.dof(),
            self.false_alarm(),
            self.threshold()
        )
    }
}

impl<T: Real + Format, const O: usize, const W: usize> Format for Detector<T, O, W> {
    fn format(&self, f: Formatter) {
        write!(
            f,
            "Detector {{ whitener: {}, test: {} }}",
            self.whitener, self.test
        )
    }
}

impl<T: Real, const S: usize, const I: usize, const O: usize, const M: usize> Format
    for ModelBank<T, S, I, O, M>
{
    fn format(&self, f: Formatter) {
        write!(
            f,
            "ModelBank {{ M: {=usize}, S: {=usize}, I: {=usize}, O: {=usize} }}",
            M, S, I, O
        )
    }
}

impl<T: Real, const S: usize, const I: usize, const M: usize, const W: usize> Format
    for BankState<T, S, I, M, W>
{
    fn format(&self, f: Formatter) {
        let steps = self.estimates.first().map_or(0, |e| e.steps());
        write!(
            f,
            "BankState {{ M: {=usize}, W: {=usize}, steps: {=u64} }}",
            M, W, steps
        )
    }
}
