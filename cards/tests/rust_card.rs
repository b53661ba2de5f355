//! The Rust route: `examples/adc_in_rust.rs` (a card implementing the
//! emulator's `Device`) answers through the ADC extension as its script
//! twin does.

#[path = "../examples/adc_in_rust.rs"]
mod adc_in_rust;

#[test]
fn the_rust_adc_card_answers_through_the_extension() {
    assert_eq!(
        adc_in_rust::answers(),
        vec![
            ("/2A0", "AC0".to_owned()),
            ("/2A1", "A57".to_owned()),
            ("/2A7", "AFF".to_owned())
        ]
    );
}
