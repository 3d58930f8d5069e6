#!/usr/bin/env python3
"""Per-function instruction breakdown and cycle estimate of the sample interrupt.

Reads QEMU's instruction trace of gyro-bench-qemu in "trace" mode (-singlestep -d
exec,nochain: one "Trace" line per executed instruction, with its PC), cuts it into
interrupts (from the first instruction of DMA2_Stream0_IRQHandler until the PC is back
in the bench loop), drops the bench's own scaffolding (bench_cb, bench_board_clear_tc:
the product's handler calls app_sample_isr directly), and for each interrupt
  * counts the instructions, in total and per function;
  * estimates Cortex-M4F cycles at 168 MHz from the executed instructions, with the
    timings of the Cortex-M4 TRM (r0p1, tables 3-1 and 7-1) and the STM32F405's flash
    (5 wait states, ART accelerator: 64 x 128-bit instruction cache lines, 8 data lines,
    sequential prefetch), for code in flash with a cold and a warm ART, and for code in
    zero-wait memory. See CycleModel for every figure and assumption.
The trace must come from a run WITHOUT -icount: under -icount QEMU logs a block whose
instruction budget ran out before it executed, and logs it again when it runs (and
re-runs I/O instructions), so a few instructions appear twice. run-bench checks every
interrupt's count against the -icount counter of a separate run of the same
(deterministic) image.
Used by tools/bench/run-bench; runnable alone on a saved log:
    isr_trace.py --elf gyro-bench-qemu.elf --log trace.log
"""
import argparse
import bisect
import json
import re
import subprocess
import sys
from collections import Counter, OrderedDict

HANDLER = "DMA2_Stream0_IRQHandler"
RETURN_TO = "run_irq"                           # the bench loop that pends the interrupt
SCAFFOLD = {"bench_cb", "bench_board_clear_tc"}  # not in the product's path
# The scaffolding sits in SRAM beside the sample path (bench_main.c), so that bench_cb
# calls app_sample_isr without a linker veneer, as the product's handler (a call through
# a pointer) does.

TRACE_RE = re.compile(rb"^Trace \d+: 0x[0-9a-f]+ \[[0-9a-f]+/([0-9a-f]+)/")
DIS_RE = re.compile(r"^\s*([0-9a-f]+):\t([0-9a-f]{4})(?: ([0-9a-f]{4}))?\s*\t(\S+)\s*(.*)$")
LIT_RE = re.compile(r"\[pc, #(-?\d+)\]")


class Insn:
    __slots__ = ("addr", "size", "mnem", "ops", "base")

    def __init__(self, addr, size, mnem, ops):
        self.addr, self.size, self.mnem, self.ops = addr, size, mnem, ops
        # mnemonic without width qualifier, data type and condition code
        m = mnem.split(".")[0]
        self.base = m


def disassemble(objdump, elf):
    out = subprocess.run([objdump, "-d", elf], check=True, capture_output=True, text=True).stdout
    insns = {}
    for line in out.splitlines():
        m = DIS_RE.match(line)
        if not m:
            continue
        addr = int(m.group(1), 16)
        size = 4 if m.group(3) else 2
        insns[addr] = Insn(addr, size, m.group(4), m.group(5).split("@")[0].strip())
    return insns


def symbols(nm, elf):
    out = subprocess.run([nm, "-S", "--defined-only", elf], check=True, capture_output=True,
                         text=True).stdout
    funcs = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "Tt":
            funcs.append((int(parts[0], 16) & ~1, int(parts[1], 16), parts[3]))
    funcs.sort()
    return funcs


def data_symbol(nm, elf, name):
    """Address of a data symbol, or None."""
    out = subprocess.run([nm, "--defined-only", elf], check=True, capture_output=True,
                         text=True).stdout
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] == name:
            return int(parts[0], 16)
    return None


class FuncMap:
    def __init__(self, funcs):
        self.starts = [f[0] for f in funcs]
        self.funcs = funcs

    def name(self, pc):
        i = bisect.bisect_right(self.starts, pc) - 1
        if i >= 0:
            start, size, name = self.funcs[i]
            if pc < start + max(size, 2):
                return name
        return "?"

    def addr(self, name):
        for start, _, n in self.funcs:
            if n == name:
                return start
        raise KeyError(name)


def read_isrs(lines, fmap):
    """Yield each interrupt as a list of PCs (scaffolding removed)."""
    handler = fmap.addr(HANDLER)
    cur = None
    for raw in lines:
        m = TRACE_RE.match(raw)
        if not m:
            continue
        pc = int(m.group(1), 16)
        if cur is None:
            if pc == handler:
                cur = [pc]
            continue
        name = fmap.name(pc)
        if name == RETURN_TO:
            yield cur
            cur = None
        elif name not in SCAFFOLD:
            cur.append(pc)


# ---------------------------------------------------------------------------------------
class CycleModel:
    """Cortex-M4F cycle estimate of an executed instruction sequence.

    Core (Cortex-M4 TRM r0p1, table 3-1; FPU table 7-1):
      data processing, MOV, CMP, IT, MUL, SMULL/UMULL     1
      MLA, MLS                                            2
      SDIV/UDIV                                           12 (the TRM's worst case)
      LDR/STR (any width), VLDR/VSTR                      2, or 1 right after a load
                                                          (address/data phases pipeline)
      LDRD/STRD                                           3
      LDM/STM/PUSH/POP, VLDM/VSTM/VPUSH/VPOP              1 + number of registers
      VADD/VSUB/VMUL/VNEG/VABS/VCMP/VCVT/VMOV/VMRS        1 (VMOV of two core regs: 2)
      VMLA/VMLS/VFMA family                               3
      VDIV, VSQRT                                         14
      taken branch, BL, BX, BLX, POP/LDR to PC            + P pipeline refill
    P = 2 (the TRM gives 1..3 by target alignment and width).
    Flash (RM0090: 5 wait states at 168 MHz, 128-bit lines; ART: 64-line instruction
    cache, 8-line data cache, prefetch): a fetched line not in the ART costs 6 cycles;
    on a taken branch the refill waits for it (+5 over P); in straight-line code the
    prefetch overlaps it with the previous line, stalling max(0, 6 - cycles spent in
    that line). Literal-pool loads go through the data cache (+5 on a miss); loads from
    the sine table in sincos_lut are taken as misses for the first of each k, k+1 pair.
    Each instruction is priced by where it sits: the image puts the sample path in SRAM
    (.ramfunc, linker/stm32f405_sections.ld), so "flash" below prices the flash model
    only for what is still fetched from flash. SRAM code has no wait states, but its
    fetches share the S-bus with data accesses to SRAM: a literal-pool load from SRAM
    code costs one cycle more, and so does a stack access (sp-relative load/store,
    PUSH/POP per register) when the image's main stack (_sstack) is in SRAM; the
    product's is in CCM (D-bus), as are the state (app_t) and the sine table (no
    contention). The sine table is priced as flash data only when the image leaves it
    in flash. "zero wait" ignores all of this (every access one cycle).
    The cache is fully associative LRU here (the ART's organisation is not documented
    in that detail), which flatters the warm case.
    """

    P = 2
    FLASH_LINE = 6
    FLASH_LO, FLASH_HI = 0x08000000, 0x08100000
    SRAM_LO, SRAM_HI = 0x20000000, 0x20020000

    FP1 = {"vadd", "vsub", "vmul", "vnmul", "vneg", "vabs", "vcmp", "vcmpe", "vcvt", "vmrs",
           "vmsr", "vcvtr", "vcvtb", "vcvtt"}
    FP3 = {"vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms"}
    FP14 = {"vdiv", "vsqrt"}
    LDST1 = {"ldr", "ldrb", "ldrh", "ldrsb", "ldrsh", "str", "strb", "strh", "vldr", "vstr",
             "ldrex", "strex", "ldrt", "strt"}
    LDS_LOAD = {"ldr", "ldrb", "ldrh", "ldrsb", "ldrsh", "vldr", "ldrex", "ldrt"}
    MULTI = {"ldm", "ldmia", "ldmdb", "ldmfd", "stm", "stmia", "stmdb", "stmfd", "push", "pop",
             "vldm", "vldmia", "vldmdb", "vstm", "vstmia", "vstmdb", "vpush", "vpop"}
    BRANCH = {"b", "bl", "bx", "blx", "cbz", "cbnz", "tbb", "tbh"}
    COND = ("eq", "ne", "cs", "cc", "hs", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt",
            "gt", "le", "al")

    def __init__(self, insns, stack_in_sram=True):
        self.insns = insns
        self.stack_in_sram = stack_in_sram

    @classmethod
    def _root(cls, base):
        if base in cls.BRANCH or base in cls.MULTI or base in cls.LDST1:
            return base
        for c in cls.COND:
            plain = cls.BRANCH | cls.LDST1 | cls.FP1 | cls.FP3 | cls.FP14 | {"vmov", "mov", "add", "sub"}
            if base.endswith(c) and base[:-2] in plain:
                return base[:-2]
        return base

    @staticmethod
    def _nregs(ops):
        m = re.search(r"\{([^}]*)\}", ops)
        if not m:
            return 1
        n = 0
        for part in m.group(1).split(","):
            part = part.strip()
            r = re.match(r"([a-z]+)(\d+)-[a-z]*(\d+)", part)
            n += (int(r.group(3)) - int(r.group(2)) + 1) if r else 1
        return n

    def cost(self, pcs, flash=True, cold=True, icache=None, dcache=None, attrib=None):
        """Cycles of one interrupt body (without exception entry/exit). attrib: (Counter,
        FuncMap) to add each instruction's cycles to its function."""
        icache = OrderedDict() if (icache is None or cold) else icache
        dcache = OrderedDict() if (dcache is None or cold) else dcache
        total = 0
        prev_load = False
        line_cycles = 0
        cur_line = None
        sine_pair_hit = False
        for i, pc in enumerate(pcs):
            ins = self.insns.get(pc)
            if ins is None:
                total += 1
                continue
            nxt = pcs[i + 1] if i + 1 < len(pcs) else None
            root = self._root(ins.base)
            ops = ins.ops
            c = 1
            is_load = False
            refill = False
            if root in self.FP14:
                c = 14
            elif root in self.FP3:
                c = 3
            elif root == "vmov":
                # a pair of core registers to or from two S or one D register: 2
                c = 2 if ops.count(",") >= 3 or (ops.count(",") == 2 and "d" in ops) else 1
            elif root in ("ldrd", "strd"):
                c = 3
            elif root in self.MULTI:
                c = 1 + self._nregs(ops)
                refill = "pc" in ops and root in ("pop", "ldm", "ldmia", "ldmfd")
            elif root in self.LDST1:
                c = 1 if prev_load else 2
                is_load = root in self.LDS_LOAD
                if is_load and re.match(r"pc\b", ops):
                    refill = True
            elif root in ("mla", "mls"):
                c = 2
            elif root in ("sdiv", "udiv"):
                c = 12
            elif root in self.BRANCH:
                c = 1
                if root in ("tbb", "tbh"):
                    c = 2
                refill = nxt is not None and nxt != pc + ins.size or root in ("bl", "blx")
            if refill:
                c += self.P
            # data from flash: literal pools (through the ART data cache), the sine table
            if flash and root in self.LDS_LOAD:
                lit = LIT_RE.search(ops)
                if lit:
                    a = ((pc + 4) & ~3) + int(lit.group(1))
                    if self.FLASH_LO <= a < self.FLASH_HI:
                        c += self._touch(dcache, a >> 4, 8) * (self.FLASH_LINE - 1)
            # SRAM code: S-bus shared by the fetch and SRAM data (literal pool, the stack
            # when it is in SRAM)
            if flash and self.SRAM_LO <= pc < self.SRAM_HI:
                stack_op = root in self.MULTI and ("sp" in ops or root in ("push", "pop", "vpush", "vpop"))
                if stack_op:
                    c += self._nregs(ops) if self.stack_in_sram else 0
                elif root in self.LDST1 | {"ldrd", "strd"} and re.search(r"\[pc\b", ops):
                    c += 1
                elif root in self.LDST1 | {"ldrd", "strd"} and re.search(r"\[sp\b", ops):
                    c += 1 if self.stack_in_sram else 0
            if flash and root == "vldr" and self._in_sincos(pc):
                c += 0 if sine_pair_hit else self.FLASH_LINE - 1
                sine_pair_hit = not sine_pair_hit
            # instruction fetch from flash
            if flash and self.FLASH_LO <= pc < self.FLASH_HI:
                line = pc >> 4
                if line != cur_line:
                    miss = self._touch(icache, line, 64)
                    if miss:
                        sequential = cur_line is not None and line == cur_line + 1
                        if sequential:
                            c += max(0, self.FLASH_LINE - line_cycles)
                        else:
                            c += self.FLASH_LINE - 1
                    cur_line, line_cycles = line, 0
            else:
                cur_line = None
            line_cycles += c
            total += c
            if attrib is not None:
                attrib[0][attrib[1].name(pc)] += c
            prev_load = is_load and not refill
        return total, icache, dcache

    _sincos = None

    def _in_sincos(self, pc):
        return self._sincos is not None and self._sincos[0] <= pc < self._sincos[1]

    def set_sincos(self, start, size):
        self._sincos = (start, start + size)

    @staticmethod
    def _touch(cache, key, cap):
        if key in cache:
            cache.move_to_end(key)
            return 0
        cache[key] = True
        if len(cache) > cap:
            cache.popitem(last=False)
        return 1


# Exception entry/exit (Cortex-M4 TRM 5.5: 12 cycles entry, 10 exit with zero-wait stack
# memory; lazy FP context (PM0214 / AN298): when the interrupted code has an active FP
# context the first FP instruction of the handler stacks S0-S15 and FPSCR, 17 words, and
# the return unstacks them).
EXC_ENTRY, EXC_EXIT, FP_LAZY_SAVE, FP_RESTORE = 12, 10, 17, 17
# Peripheral accesses of the handler and the HAL calls per tick, counted in the source
# (every converter stream is circular and timer-started, so nothing is re-armed):
#   DMA2_Stream0_IRQHandler (stm32f4_sample.c): reads DMA2 LISR twice (the flags, the
#     overrun check after the tick); writes DMA2 LIFCR once;
#   hal_dac_write_frame (stm32f4_dac.c): reads TIM1 CNT (the deadline); its four words
#     go to SRAM;
#   DMA2_Stream0_IRQHandler's self-measurement, twice: reads DWT CYCCNT.
# Reads: DMA2 (AHB1) 2, TIM1 (APB2) 1, DWT (PPB) 2; writes: DMA2 1.
# Assumed extra cycles over an SRAM access: AHB1 read +2, APB2 read +4 (bridge at
# HCLK/2), PPB read +1, write +1.
PERIPH_EXTRA = 2 * 2 + 1 * 4 + 2 * 1 + 1 * 1


def job_functions(isrs, fmap):
    sets = [sorted({fmap.name(pc) for pc in pcs}) for pcs in isrs]
    common = set(sets[0]).intersection(*sets[1:]) if sets else set()
    return [[f for f in s if f not in common] for s in sets]


def analyse(lines, elf, objdump="arm-none-eabi-objdump", nm="arm-none-eabi-nm", summary_n=None):
    """The trace's interrupts: per-interrupt counts and cycles (insns_each, cycles_each,
    job_functions_each) for every one, the means, mixes and memory models over the first
    summary_n (all if None: a trace of several modes summarises its first)."""
    insns = disassemble(objdump, elf)
    funcs = symbols(nm, elf)
    fmap = FuncMap(funcs)
    sstack = data_symbol(nm, elf, "_sstack")
    if sstack is None:
        raise RuntimeError("no _sstack in the image: where its stack sits sets its cost")
    stack_in_sram = CycleModel.SRAM_LO <= sstack < CycleModel.SRAM_HI
    model = CycleModel(insns, stack_in_sram)
    table = data_symbol(nm, elf, "sincos_table")
    table_in_flash = table is not None and CycleModel.FLASH_LO <= table < CycleModel.FLASH_HI
    for start, size, name in funcs:
        if name == "sincos_lut" and table_in_flash:
            model.set_sincos(start, size)
    all_isrs = list(read_isrs(lines, fmap))
    if not all_isrs:
        raise RuntimeError("no interrupt found in the trace")
    all_counts = [len(p) for p in all_isrs]
    isrs = all_isrs[:summary_n] if summary_n else all_isrs
    counts = [len(p) for p in isrs]
    per_func = Counter()
    mix = Counter()
    for pcs in isrs:
        for pc in pcs:
            per_func[fmap.name(pc)] += 1
            ins = insns.get(pc)
            mix[CycleModel._root(ins.base) if ins else "?"] += 1
    n = len(isrs)
    worst = max(range(n), key=lambda i: counts[i])
    # cycles: mean and worst over the traced interrupts, three memory models
    res = {}
    ic = dc = None
    warm = []
    for pcs in isrs:
        cyc, ic, dc = model.cost(pcs, flash=True, cold=False, icache=ic, dcache=dc)
        warm.append(cyc)
    cyc_cold, cyc_sram = Counter(), Counter()
    cold = [model.cost(p, flash=True, cold=True, attrib=(cyc_cold, fmap))[0] for p in isrs]
    cold_all = cold + [model.cost(p, flash=True, cold=True)[0] for p in all_isrs[len(isrs):]]
    sram = [model.cost(p, flash=False, attrib=(cyc_sram, fmap))[0] for p in isrs]
    lines_touched = len({pc >> 4 for pc in isrs[worst] if CycleModel.FLASH_LO <= pc < CycleModel.FLASH_HI})
    overhead_best = EXC_ENTRY + EXC_EXIT
    overhead_worst = EXC_ENTRY + EXC_EXIT + FP_LAZY_SAVE + FP_RESTORE
    for key, vals in (("flash_cold", cold), ("flash_warm", warm), ("zero_wait", sram)):
        res[key] = {
            "body_mean": sum(vals) / n,
            "body_max": max(vals),
            "total_mean": sum(vals) / n + overhead_worst + PERIPH_EXTRA,
            "total_max": max(vals) + overhead_worst + PERIPH_EXTRA,
        }
    return {
        "interrupts": n,
        "insns_mean": sum(counts) / n,
        "insns_min": min(counts),
        "insns_max": max(counts),
        "insns_each": all_counts,
        "cycles_each": cold_all,  # as linked, ART cold: one per interrupt, in order
        # the functions each interrupt ran beyond those every interrupt runs (its job)
        "job_functions_each": job_functions(all_isrs, fmap),
        "per_function_mean": {k: v / n for k, v in per_func.most_common()},
        "per_function_cycles_mean": {k: {"flash_cold": cyc_cold[k] / n, "zero_wait": cyc_sram[k] / n}
                                     for k, _ in cyc_cold.most_common()},
        "mix_mean": {k: v / n for k, v in mix.most_common()},
        "flash_lines_touched_worst": lines_touched,
        "exception_overhead": {"entry": EXC_ENTRY, "exit": EXC_EXIT, "fp_lazy_save": FP_LAZY_SAVE,
                               "fp_restore": FP_RESTORE, "best": overhead_best,
                               "worst": overhead_worst},
        "peripheral_extra": PERIPH_EXTRA,
        "cycles": res,
        "budget_cycles": 0.2 * 3360,
        "stack_in_sram": stack_in_sram,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elf", required=True)
    ap.add_argument("--log", required=True, help="QEMU -d exec,nochain log ('-' = stdin)")
    ap.add_argument("--objdump", default="arm-none-eabi-objdump")
    ap.add_argument("--nm", default="arm-none-eabi-nm")
    args = ap.parse_args()
    f = sys.stdin.buffer if args.log == "-" else open(args.log, "rb")
    print(json.dumps(analyse(f, args.elf, args.objdump, args.nm), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
