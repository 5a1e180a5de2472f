//! Instruction counts of spans of the run.
//!
//! On the device, SysTick runs from the processor clock (25 MHz on qemu's mps2 boards) and qemu
//! runs with `-icount shift=0`: every guest instruction advances virtual time by exactly 1 ns, so
//! one SysTick tick is 40 instructions and a span's tick count is a deterministic instruction
//! count (to within one tick). [`calibrate`] measures the ratio at boot with a loop of a known
//! number of instructions rather than trusting the 40; the counter is 24 bits, so the SysTick
//! handler counts wraps and long spans work.
//!
//! On the host there is no such clock: spans measure nothing and the lines that would print
//! them are left out.

/// A running measurement.
#[derive(Clone, Copy, Debug)]
pub struct Span {
    #[cfg(target_os = "none")]
    start: u64,
}

#[cfg(target_os = "none")]
mod systick {
    use core::sync::atomic::{AtomicU32, Ordering};

    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m::peripheral::{SCB, SYST};

    /// The reload value: the full 24 bits, so the counter wraps every 2^24 ticks.
    const RELOAD: u32 = 0x00FF_FFFF;

    /// SysTick wraps so far (the exception handler counts them).
    static WRAPS: AtomicU32 = AtomicU32::new(0);
    /// Instructions per tick, as [`super::calibrate`] measured them.
    pub(super) static RATE: AtomicU32 = AtomicU32::new(40);

    /// Starts SysTick from the processor clock, interrupting on every wrap; returns once the
    /// counter has loaded `RELOAD` (time 0 of [`ticks`]).
    pub fn start(mut syst: SYST) {
        syst.disable_counter();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        // Writing VAL clears it to 0; the counter loads RELOAD on the next tick (no wrap).
        syst.clear_current();
        syst.enable_interrupt();
        syst.enable_counter();
        while SYST::get_current() == 0 {}
    }

    /// Called by the SysTick exception handler.
    pub fn on_wrap() {
        WRAPS.fetch_add(1, Ordering::Relaxed);
    }

    /// Ticks since [`start`], 64 bits.
    ///
    /// The counter runs `RELOAD, ..., 1, 0` and pends the exception as it reaches 0, so `n`
    /// arrivals at 0 and a current value `v` mean `(n - [v == 0]) (RELOAD + 1) + RELOAD - v`
    /// ticks. `n` is the handler's count plus a wrap still pending (read with interrupts off, the
    /// pending bit before and after the counter telling whether the wrap came in between).
    #[inline(never)]
    pub fn ticks() -> u64 {
        cortex_m::interrupt::free(|_| loop {
            let before = SCB::is_pendst_pending();
            let current = SYST::get_current();
            let after = SCB::is_pendst_pending();
            if before != after {
                continue;
            }
            let arrivals = WRAPS.load(Ordering::Relaxed) as u64 + after as u64;
            let periods = arrivals.saturating_sub((current == 0) as u64);
            return periods * (RELOAD as u64 + 1) + (RELOAD - current) as u64;
        })
    }
}

#[cfg(target_os = "none")]
pub use systick::{on_wrap, start};

impl Span {
    /// Starts a span now.
    #[inline(always)]
    pub fn start() -> Span {
        Span {
            #[cfg(target_os = "none")]
            start: systick::ticks(),
        }
    }

    /// Instructions since [`Span::start`]; `None` where nothing counts them (the host).
    #[inline(always)]
    pub fn instructions(&self) -> Option<u64> {
        #[cfg(target_os = "none")]
        {
            use core::sync::atomic::Ordering;
            let ticks = systick::ticks() - self.start;
            Some(ticks * systick::RATE.load(Ordering::Relaxed) as u64)
        }
        #[cfg(not(target_os = "none"))]
        {
            None
        }
    }
}

/// What [`calibrate`] found.
#[cfg(target_os = "none")]
#[derive(Clone, Copy, Debug)]
pub struct Calibration {
    /// Instructions the longer loop runs more than the shorter one.
    pub instructions: u64,
    /// SysTick ticks the longer loop takes more than the shorter one.
    pub ticks: u64,
    /// `instructions / ticks`, rounded: what spans multiply their ticks by from now on.
    pub per_tick: u32,
}

/// Runs `subs; bne` loops of 1,000,000 and 2,000,000 iterations (2 instructions each) and
/// compares their SysTick ticks: the difference, 2,000,000 instructions, cancels the
/// measurement's own overhead. Sets the rate spans use.
#[cfg(target_os = "none")]
pub fn calibrate() -> Calibration {
    use core::sync::atomic::Ordering;

    fn loop_ticks(iterations: u32) -> u64 {
        let t0 = systick::ticks();
        // SAFETY: a register-only countdown loop; it touches no memory and no stack.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {n}, {n}, #1",
                "bne 2b",
                n = inout(reg) iterations => _,
                options(nomem, nostack),
            );
        }
        systick::ticks() - t0
    }

    let short = loop_ticks(1_000_000);
    let long = loop_ticks(2_000_000);
    let ticks = long.saturating_sub(short).max(1);
    let instructions = 2 * 1_000_000u64;
    let per_tick = ((instructions + ticks / 2) / ticks) as u32;
    systick::RATE.store(per_tick.max(1), Ordering::Relaxed);
    Calibration {
        instructions,
        ticks,
        per_tick,
    }
}
