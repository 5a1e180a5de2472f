//! The device side: entry point, exception handlers, panic handler, stack measurement. Output
//! goes to the host over semihosting, and the run ends with a semihosting exit (qemu needs
//! `-semihosting-config enable=on,target=native`).

use core::panic::PanicInfo;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};

use crate::{clock, frames, HIERARCHY};

/// What cortex-m-rt's `paint-stack` writes between `_stack_end` and `_stack_start` before main.
const STACK_PAINT: u32 = 0xCCCC_CCCC;

#[entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        hprintln!("error=peripherals taken");
        fail();
    };
    clock::start(peripherals.SYST);
    let c = clock::calibrate();
    hprintln!(
        "systick_calibration loop_instructions={} ticks={} instructions_per_tick={}",
        c.instructions,
        c.ticks,
        c.per_tick
    );

    let result = frames::run_frames(HIERARCHY, &mut |r| hprintln!("{}", r));
    if let Err(e) = result {
        hprintln!("error={}", e);
        fail();
    }
    let (stack, painted) = peak_stack();
    hprintln!("stack_bytes={} stack_region_bytes={}", stack, painted);
    debug::exit(debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::wfi();
    }
}

/// Peak stack use in bytes: from `_stack_start` (the initial stack pointer) down to the lowest
/// word the paint no longer holds; and the size of the painted region.
fn peak_stack() -> (usize, usize) {
    extern "C" {
        static _stack_end: u32;
        static _stack_start: u32;
    }
    // Only the symbols' addresses are taken: nothing is read through them.
    let bottom = core::ptr::addr_of!(_stack_end) as usize;
    let top = core::ptr::addr_of!(_stack_start) as usize;
    let mut p = bottom;
    // SAFETY: `_stack_end.._stack_start` is RAM the linker script reserves for the stack (and
    // nothing else: no heap); words below the live stack pointer are read as plain memory.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == STACK_PAINT {
        p += 4;
    }
    (top - p, top - bottom)
}

fn fail() -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[exception]
fn SysTick() {
    clock::on_wrap();
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("error=hard fault at pc={:#010x}", frame.pc());
    fail();
}

#[exception]
unsafe fn DefaultHandler(irq: i16) {
    hprintln!("error=unexpected exception {}", irq);
    fail();
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    hprintln!("error=panic: {}", info);
    fail();
}
