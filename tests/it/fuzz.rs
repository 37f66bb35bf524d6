//! Every shipped preset file, mutated (truncated, a byte flipped, a number
//! replaced by 0, a negative, NaN or a huge value, two names swapped):
//! never a panic; each mutant either is refused with a one-line message,
//! or loads and steps with no NaN in a `Transform` (a bead whose state
//! blows up is marked diverged, not hidden).
//!
//! A debug `cargo test` tries [`DEBUG_CASES`] mutants of each file; a
//! release build (`cargo test --release --test it fuzz`, as CI runs it)
//! the full [`RELEASE_CASES`], 200,000 over the 20 shipped files.

use bevy::prelude::*;
use proptest::prelude::*;
use std::cell::RefCell;

use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use wirebead::headless::{Headless, run_steps};
use wirebead::prelude::*;
use wirebead::preset::FromPreset;
use wirebead::{NextParams, ScenePreset};

use crate::presets::{SHIPPED, shipped_dir};

/// One way to spoil a file.
#[derive(Clone, Debug)]
enum Mutation {
    /// Cut the file at this fraction of its length.
    Truncate(f64),
    /// Flip one bit of the byte at this fraction of the length.
    FlipByte(f64, u8),
    /// Replace the k-th number (mod their count) by this text.
    Number(usize, &'static str),
    /// Swap the i-th and j-th quoted strings (mod their count).
    SwapNames(usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0..1.0f64).prop_map(Mutation::Truncate),
        (0.0..1.0f64, 0..8u8).prop_map(|(at, bit)| Mutation::FlipByte(at, bit)),
        (
            any::<usize>(),
            prop::sample::select(vec![
                "0", "0.0", "-1.0", "-2.5e3", "NaN", "inf", "1e300", "-1e300"
            ])
        )
            .prop_map(|(k, to)| Mutation::Number(k, to)),
        (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Mutation::SwapNames(i, j)),
    ]
}

/// The spans of `text` that are number literals.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        let in_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if starts && !in_word {
            let start = i;
            i += 1;
            while i < bytes.len()
                && (bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'e' | b'E' | b'-'))
            {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// The spans of `text` inside double quotes.
fn quoted(text: &str) -> Vec<(usize, usize)> {
    let starts: Vec<usize> = text.match_indices('"').map(|(i, _)| i).collect();
    starts
        .chunks_exact(2)
        .map(|pair| (pair[0] + 1, pair[1]))
        .collect()
}

fn apply(text: &str, mutation: &Mutation) -> String {
    let at = |fraction: f64| ((fraction * text.len() as f64) as usize).min(text.len());
    match *mutation {
        Mutation::Truncate(f) => String::from_utf8_lossy(&text.as_bytes()[..at(f)]).into_owned(),
        Mutation::FlipByte(f, bit) => {
            let mut bytes = text.as_bytes().to_vec();
            if let Some(b) = bytes.get_mut(at(f)) {
                *b ^= 1 << bit;
            }
            String::from_utf8_lossy(&bytes).into_owned()
        }
        Mutation::Number(k, to) => {
            let spans = numbers(text);
            let Some(&(a, b)) = spans.get(k % spans.len().max(1)) else {
                return text.to_owned();
            };
            format!("{}{to}{}", &text[..a], &text[b..])
        }
        Mutation::SwapNames(i, j) => {
            let spans = quoted(text);
            if spans.len() < 2 {
                return text.to_owned();
            }
            let (mut x, mut y) = (spans[i % spans.len()], spans[j % spans.len()]);
            if x.0 > y.0 {
                std::mem::swap(&mut x, &mut y);
            }
            if x == y {
                return text.to_owned();
            }
            format!(
                "{}{}{}{}{}",
                &text[..x.0],
                &text[y.0..y.1],
                &text[x.1..y.0],
                &text[x.0..x.1],
                &text[y.1..]
            )
        }
    }
}

/// Loads `text` into `app` (replacing the scene before it) and steps it,
/// or checks the refusal is one line.
fn load_and_step(app: &mut App, text: &str) -> Result<(), TestCaseError> {
    let preset = match ScenePreset::from_ron(text) {
        Err(e) => {
            let message = e.to_string();
            prop_assert!(
                !message.is_empty() && !message.contains('\n'),
                "{message:?}"
            );
            return Ok(());
        }
        Ok(preset) => preset,
    };
    let world = app.world_mut();
    let old: Vec<Entity> = world
        .query_filtered::<Entity, With<FromPreset>>()
        .iter(world)
        .collect();
    for entity in old {
        world.despawn(entity);
    }
    world
        .resource_mut::<NextParams>()
        .set(preset.params.clone())
        .map_err(|e| TestCaseError::fail(format!("validated params refused: {e}")))?;
    preset.spawn(&mut world.commands());
    world.flush();
    world.write_message(Restart);
    run_steps(app, 3);
    let world = app.world_mut();
    let mut beads = world.query::<(&BeadPosition, &BeadVelocity, &Transform, Has<Diverged>)>();
    for (position, velocity, transform, diverged) in beads.iter(world) {
        prop_assert!(transform.translation.is_finite(), "a NaN in a Transform");
        prop_assert!(
            diverged || (position.is_finite() && velocity.is_finite()),
            "a bead went non-finite without being marked diverged"
        );
    }
    Ok(())
}

/// Mutants of each file in a debug build: a few hundred in all.
const DEBUG_CASES: u32 = 25;
/// Mutants of each file in a release build.
const RELEASE_CASES: u32 = 10_000;

#[test]
fn mutated_presets_never_panic_and_never_leave_a_nan() {
    let cases = if cfg!(debug_assertions) {
        DEBUG_CASES
    } else {
        RELEASE_CASES
    };
    for name in SHIPPED {
        let text = std::fs::read_to_string(shipped_dir().join(name)).unwrap();
        let app = RefCell::new(
            Headless::new(WireBeadPlugin::default())
                .single_threaded()
                .build(),
        );
        // A fixed seed: the same mutants on every run (the debug ones are
        // the first of the release ones).
        let mut runner = TestRunner::new_with_rng(
            Config {
                cases,
                failure_persistence: None,
                ..Config::default()
            },
            TestRng::deterministic_rng(RngAlgorithm::ChaCha),
        );
        runner
            .run(&mutation(), |m| {
                load_and_step(&mut app.borrow_mut(), &apply(&text, &m))
            })
            .unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}
