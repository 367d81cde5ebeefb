/* The LLVM pass of a host-built F28335 firmware (sins-fw build-firmware), loaded by clang with
   -fpass-plugin: it turns the firmware's register accesses, and in the C28x float mode its
   floating-point operations, into calls to the runtime (firmware_c/runtime/sins_fw_runtime.cpp).

   Raw addresses. An integer constant in the C28x data space (0 < address < 0x400000) made a pointer
   becomes the address of that word in the runtime's image of the data space (map_raw_addresses).

   Register accesses. Every volatile load and store, and every load and store whose address is based
   on one of the register-file objects named in $SINS_FW_PASS_SYMBOLS (comma-separated: TI declares
   PieVectTable without `volatile`) or on a vector-table image (a global of PieVectTable's type, TI's
   PieVectTableInit), becomes a call `sins_fw_ldN(address)` / `sins_fw_stN(address, value)` for N = 8,
   16, 32, 64 bits (a float, double or pointer travels as the integer of its size); a memcpy, memmove
   or memset with such an address becomes `sins_fw_memcpy` / `sins_fw_memset`. "Based on" follows the
   pointer's provenance through the module (RegisterPointers): GEPs, casts, phis and selects, the
   local variables and globals a based pointer is stored in (TI's InitPieVectTable: `Uint32 *Dest =
   (void *)&PieVectTable; *Dest++ = *Source++;`), and the parameters of the module's functions it is
   passed to. A pointer that reaches an access otherwise (through a struct field, another
   translation unit's function) is not followed: such an access must be volatile, as TI's headers
   declare every register file but PieVectTable. A vector-table image registers itself with the
   runtime at load time (sins_fw_vector_image), so that a 32-bit word of it, as TI's copy reads one,
   is the vector it holds.
   Definitions of the register-file objects (TI's DSP2833x_GlobalVariableDefs.c: `volatile struct
   SPI_REGS SpiaRegs;`) become declarations: the build places the objects itself.
   The runtime tells by the address what it is: a register of the C28x data space (a raw address such
   as `*(volatile Uint16 *)0x701B`, or a field of a register-file object, which the link places in the
   runtime's image of the data space), the vector table, IER/IFR, or ordinary host memory (a volatile
   global of the firmware), which it reads or writes as it is. The C front end has already lowered a
   bit-field store to a load, the masking and a store of the whole storage unit, so a bit-field store
   is a read-modify-write of the word, as on the C28x. The pass runs at the start of the optimisation
   pipeline, before any volatile access could be merged or split.

   C28x float ($SINS_FW_PASS_C28X_FLOAT=1). Every float operation becomes the c28x-f32 backend's
   (rust/core/src/numerics/c28x.rs through the C ABI): + − × ÷ and negation, the conversions from and
   to integers and from double, and the math library's float and double functions on float arguments
   (the build has made the firmware's `double` a `float`, as TI's COFF ABI does). Comparisons, loads
   and stores stay as they are: the values are always canonical. */
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "llvm/Analysis/ValueTracking.h"
#include "llvm/IR/GlobalVariable.h"
#include "llvm/IR/IRBuilder.h"
#include "llvm/IR/InstIterator.h"
#include "llvm/IR/Instructions.h"
#include "llvm/IR/IntrinsicInst.h"
#include "llvm/IR/Module.h"
#include "llvm/IR/PassManager.h"
#include "llvm/Passes/PassBuilder.h"
#include "llvm/Passes/PassPlugin.h"
#include "llvm/Transforms/Utils/ModuleUtils.h"

using namespace llvm;

namespace {

std::set<std::string> symbols_from_env() {
    std::set<std::string> out;
    const char *env = std::getenv("SINS_FW_PASS_SYMBOLS");
    if (env == nullptr) {
        return out;
    }
    std::string s(env);
    size_t start = 0;
    while (start <= s.size()) {
        size_t comma = s.find(',', start);
        if (comma == std::string::npos) {
            comma = s.size();
        }
        if (comma > start) {
            out.insert(s.substr(start, comma - start));
        }
        start = comma + 1;
    }
    return out;
}

/* Whether `t` is TI's vector table type (struct PIE_VECT_TABLE; clang may add a suffix: .0, ...). */
bool is_vector_table_type(Type *t) {
    auto *st = dyn_cast<StructType>(t);
    return st != nullptr && st->hasName() &&
           (st->getName() == "struct.PIE_VECT_TABLE" || st->getName().startswith("struct.PIE_VECT_TABLE."));
}

/* The pointer values of a module that may point into a register-file object or a vector-table image
   (the roots): a module-wide fixpoint over GEPs, casts, phis and selects of such values, loads from
   the memory objects (allocas, globals) such a value is stored in, and the parameters such a value
   is passed to. Provenance, not addresses: the runtime still tells by the address what an access
   reaches, so following a pointer that may also point elsewhere costs time only. */
struct RegisterPointers {
    std::set<const Value *> based;
    std::set<const Value *> slots; /* memory objects that hold a based pointer */
    const std::set<std::string> &symbols;
    std::set<const GlobalVariable *> images;

    explicit RegisterPointers(Module &m, const std::set<std::string> &syms) : symbols(syms) {
        for (GlobalVariable &g : m.globals()) {
            if (is_vector_table_type(g.getValueType()) && symbols.count(g.getName().str()) == 0) {
                images.insert(&g);
            }
        }
        for (GlobalVariable &g : m.globals()) {
            if (g.hasInitializer() && g.getValueType()->isPointerTy() && is_based(g.getInitializer())) {
                slots.insert(&g);
            }
        }
        bool more = true;
        while (more) {
            more = false;
            for (Function &f : m) {
                for (Instruction &i : instructions(f)) {
                    more |= visit(i);
                }
            }
        }
    }

    bool is_root(const Value *v) const {
        const auto *g = dyn_cast<GlobalVariable>(v);
        return g != nullptr && (symbols.count(g->getName().str()) != 0 || images.count(g) != 0);
    }

    bool is_based(const Value *v) const {
        if (based.count(v) != 0) {
            return true;
        }
        if (isa<Constant>(v) || isa<GlobalValue>(v)) {
            return is_root(getUnderlyingObject(v, 0));
        }
        return false;
    }

    bool add(const Value *v) { return based.insert(v).second; }

    bool visit(Instruction &i) {
        if (!i.getType()->isPointerTy() && !isa<StoreInst>(&i) && !isa<CallBase>(&i)) {
            return false;
        }
        if (auto *gep = dyn_cast<GetElementPtrInst>(&i)) {
            return is_based(gep->getPointerOperand()) && add(&i);
        }
        if (isa<BitCastInst>(&i) || isa<AddrSpaceCastInst>(&i)) {
            return is_based(i.getOperand(0)) && add(&i);
        }
        if (auto *phi = dyn_cast<PHINode>(&i)) {
            for (Value *v : phi->incoming_values()) {
                if (is_based(v)) {
                    return add(&i);
                }
            }
            return false;
        }
        if (auto *sel = dyn_cast<SelectInst>(&i)) {
            return (is_based(sel->getTrueValue()) || is_based(sel->getFalseValue())) && add(&i);
        }
        if (auto *ld = dyn_cast<LoadInst>(&i)) {
            return slots.count(getUnderlyingObject(ld->getPointerOperand(), 0)) != 0 && add(&i);
        }
        if (auto *st = dyn_cast<StoreInst>(&i)) {
            if (!st->getValueOperand()->getType()->isPointerTy() || !is_based(st->getValueOperand())) {
                return false;
            }
            const Value *slot = getUnderlyingObject(st->getPointerOperand(), 0);
            return (isa<AllocaInst>(slot) || isa<GlobalVariable>(slot)) && slots.insert(slot).second;
        }
        if (auto *call = dyn_cast<CallBase>(&i)) {
            bool changed = false;
            Function *fn = call->getCalledFunction();
            if (fn != nullptr && !fn->isDeclaration()) {
                for (unsigned k = 0; k < call->arg_size() && k < fn->arg_size(); k++) {
                    if (call->getArgOperand(k)->getType()->isPointerTy() && is_based(call->getArgOperand(k))) {
                        changed |= add(fn->getArg(k));
                    }
                }
            }
            return changed;
        }
        return false;
    }
};

struct SinsFwPass : PassInfoMixin<SinsFwPass> {
    std::set<std::string> symbols = symbols_from_env();
    bool c28x_float = [] {
        const char *env = std::getenv("SINS_FW_PASS_C28X_FLOAT");
        return env != nullptr && std::strcmp(env, "1") == 0;
    }();

    /* The access width in bits of a type the runtime can carry (0: none). */
    static unsigned width(Type *t, const DataLayout &dl) {
        if (t->isIntegerTy(8) || t->isIntegerTy(16) || t->isIntegerTy(32) || t->isIntegerTy(64) ||
            t->isFloatTy() || t->isDoubleTy() || t->isPointerTy()) {
            return static_cast<unsigned>(dl.getTypeSizeInBits(t).getFixedSize());
        }
        return 0;
    }

    bool instrument_accesses(Function &f, Module &m, const RegisterPointers &reg) {
        const DataLayout &dl = m.getDataLayout();
        LLVMContext &ctx = m.getContext();
        Type *i8p = Type::getInt8PtrTy(ctx);
        Type *i8 = Type::getInt8Ty(ctx);
        Type *i64 = Type::getInt64Ty(ctx);
        std::vector<Instruction *> work;
        for (Instruction &i : instructions(f)) {
            if (auto *ld = dyn_cast<LoadInst>(&i)) {
                if (!ld->isAtomic() && width(ld->getType(), dl) != 0 &&
                    (ld->isVolatile() || reg.is_based(ld->getPointerOperand()))) {
                    work.push_back(ld);
                }
            } else if (auto *st = dyn_cast<StoreInst>(&i)) {
                if (!st->isAtomic() && width(st->getValueOperand()->getType(), dl) != 0 &&
                    (st->isVolatile() || reg.is_based(st->getPointerOperand()))) {
                    work.push_back(st);
                }
            } else if (auto *mt = dyn_cast<MemTransferInst>(&i)) {
                if (reg.is_based(mt->getRawDest()) || reg.is_based(mt->getRawSource())) {
                    work.push_back(mt);
                }
            } else if (auto *ms = dyn_cast<MemSetInst>(&i)) {
                if (reg.is_based(ms->getRawDest())) {
                    work.push_back(ms);
                }
            }
        }
        for (Instruction *i : work) {
            IRBuilder<> b(i);
            if (auto *mt = dyn_cast<MemTransferInst>(i)) {
                /* Word by word through the runtime (memmove's overlap cannot involve a register
                   file and host memory at once: the runtime copies forwards or backwards as memmove). */
                FunctionCallee fn = m.getOrInsertFunction("sins_fw_memcpy", Type::getVoidTy(ctx), i8p, i8p, i64);
                b.CreateCall(fn, {b.CreatePointerCast(mt->getRawDest(), i8p), b.CreatePointerCast(mt->getRawSource(), i8p),
                                  b.CreateZExtOrTrunc(mt->getLength(), i64)});
                mt->eraseFromParent();
                continue;
            }
            if (auto *ms = dyn_cast<MemSetInst>(i)) {
                FunctionCallee fn = m.getOrInsertFunction("sins_fw_memset", Type::getVoidTy(ctx), i8p, i8, i64);
                b.CreateCall(fn, {b.CreatePointerCast(ms->getRawDest(), i8p), ms->getValue(),
                                  b.CreateZExtOrTrunc(ms->getLength(), i64)});
                ms->eraseFromParent();
                continue;
            }
            if (auto *ld = dyn_cast<LoadInst>(i)) {
                Type *t = ld->getType();
                unsigned w = width(t, dl);
                IntegerType *it = IntegerType::get(ctx, w);
                FunctionCallee fn = m.getOrInsertFunction("sins_fw_ld" + std::to_string(w), it, i8p);
                Value *addr = b.CreatePointerCast(ld->getPointerOperand(), i8p);
                Value *v = b.CreateCall(fn, {addr});
                if (t->isPointerTy()) {
                    v = b.CreateIntToPtr(v, t);
                } else if (t != it) {
                    v = b.CreateBitCast(v, t);
                }
                ld->replaceAllUsesWith(v);
                ld->eraseFromParent();
            } else {
                auto *st = cast<StoreInst>(i);
                Value *val = st->getValueOperand();
                Type *t = val->getType();
                unsigned w = width(t, dl);
                IntegerType *it = IntegerType::get(ctx, w);
                FunctionCallee fn =
                    m.getOrInsertFunction("sins_fw_st" + std::to_string(w), Type::getVoidTy(ctx), i8p, it);
                Value *addr = b.CreatePointerCast(st->getPointerOperand(), i8p);
                if (t->isPointerTy()) {
                    val = b.CreatePtrToInt(val, it);
                } else if (t != it) {
                    val = b.CreateBitCast(val, it);
                }
                b.CreateCall(fn, {addr, val});
                st->eraseFromParent();
            }
        }
        return !work.empty();
    }

    /* A raw C28x data address made a pointer (`(volatile Uint16 *)0x701B`): the same word of the
       runtime's image of the data space, `sins_fw_io + 2·address`, so that the pointer's arithmetic
       counts 16-bit words as on the C28x. Constants (in code and in initialisers) become constant
       addresses; a conversion of a run-time integer calls the runtime's sins_fw_ptr, which maps the
       data space the same way and leaves any other value (a host address made an integer and back)
       as it is. Null stays null. */
    static bool is_data_address(const Constant *c) {
        const auto *ci = dyn_cast<ConstantInt>(c);
        return ci != nullptr && ci->getValue().getActiveBits() <= 32 && ci->getZExtValue() != 0 &&
               ci->getZExtValue() < 0x400000u;
    }

    static void collect_raw(Constant *c, std::set<ConstantExpr *> &out, std::set<Constant *> &seen) {
        if (!seen.insert(c).second) {
            return;
        }
        if (auto *ce = dyn_cast<ConstantExpr>(c)) {
            if (ce->getOpcode() == Instruction::IntToPtr && is_data_address(ce->getOperand(0))) {
                out.insert(ce);
                return;
            }
        }
        for (Use &u : c->operands()) {
            if (auto *op = dyn_cast<Constant>(u.get())) {
                collect_raw(op, out, seen);
            }
        }
    }

    bool map_raw_addresses(Module &m) {
        LLVMContext &ctx = m.getContext();
        Type *i8 = Type::getInt8Ty(ctx);
        Type *i64 = Type::getInt64Ty(ctx);
        std::set<ConstantExpr *> raw;
        std::set<Constant *> seen;
        std::vector<IntToPtrInst *> dynamic;
        for (Function &f : m) {
            for (Instruction &i : instructions(f)) {
                if (auto *itp = dyn_cast<IntToPtrInst>(&i)) {
                    if (auto *c = dyn_cast<Constant>(itp->getOperand(0))) {
                        if (is_data_address(c)) {
                            dynamic.push_back(itp); /* a constant still: mapped as one below */
                        }
                    } else {
                        dynamic.push_back(itp);
                    }
                }
                for (Use &u : i.operands()) {
                    if (auto *c = dyn_cast<Constant>(u.get())) {
                        collect_raw(c, raw, seen);
                    }
                }
            }
        }
        for (GlobalVariable &g : m.globals()) {
            if (g.hasInitializer()) {
                collect_raw(g.getInitializer(), raw, seen);
            }
        }
        if (raw.empty() && dynamic.empty()) {
            return false;
        }
        Constant *io = m.getOrInsertGlobal("sins_fw_io", i8);
        for (ConstantExpr *ce : raw) {
            uint64_t address = cast<ConstantInt>(ce->getOperand(0))->getZExtValue();
            Constant *at = ConstantExpr::getGetElementPtr(i8, io, ConstantInt::get(i64, 2 * address));
            ce->replaceAllUsesWith(ConstantExpr::getPointerCast(at, ce->getType()));
        }
        FunctionCallee map = m.getOrInsertFunction("sins_fw_ptr", Type::getInt8PtrTy(ctx), i64);
        for (IntToPtrInst *itp : dynamic) {
            IRBuilder<> b(itp);
            Value *v = b.CreateZExtOrTrunc(itp->getOperand(0), i64);
            Value *p = b.CreatePointerCast(b.CreateCall(map, {v}), itp->getType());
            itp->replaceAllUsesWith(p);
            itp->eraseFromParent();
        }
        return true;
    }

    /* The backend's function for a math library call on float values (nullptr: none). */
    static const char *math_model(StringRef name, unsigned *args) {
        static const struct {
            const char *c;
            const char *model;
            unsigned args;
        } table[] = {
            {"sqrt", "sins_c28x_sqrt", 1}, {"sin", "sins_c28x_sin", 1},   {"cos", "sins_c28x_cos", 1},
            {"atan", "sins_c28x_atan", 1}, {"asin", "sins_c28x_asin", 1}, {"acos", "sins_c28x_acos", 1},
            {"tan", "sins_c28x_tan", 1},   {"exp", "sins_c28x_exp", 1},   {"log", "sins_c28x_log", 1},
            {"fabs", "sins_c28x_abs", 1},  {"atan2", "sins_c28x_atan2", 2}, {"pow", "sins_c28x_pow", 2},
        };
        for (const auto &e : table) {
            if (name == e.c || name == std::string(e.c) + "f" || name == std::string("llvm.") + e.c + ".f32" ||
                name == std::string("llvm.") + e.c + ".f64") {
                *args = e.args;
                return e.model;
            }
        }
        return nullptr;
    }

    bool instrument_floats(Function &f, Module &m) {
        LLVMContext &ctx = m.getContext();
        Type *fl = Type::getFloatTy(ctx);
        Type *db = Type::getDoubleTy(ctx);
        Type *i32 = Type::getInt32Ty(ctx);
        /* The backend's operations are pure functions of their operands (c28x-f32's rounding is
           fixed): declared so, the optimiser treats them as it treats the float instructions they
           replace (common subexpressions, loop-invariant motion), as cl2000 does for FPU code, and
           the cycles the pass prices later are those of the optimised code (docs/c-cycles.md). */
        auto callee = [&](const char *name, Type *ret, ArrayRef<Type *> params) {
            FunctionCallee c = m.getOrInsertFunction(name, FunctionType::get(ret, params, false));
            if (auto *fn = dyn_cast<Function>(c.getCallee())) {
                fn->setDoesNotAccessMemory();
                fn->setDoesNotThrow();
                fn->addFnAttr(Attribute::WillReturn);
            }
            return c;
        };
        std::vector<Instruction *> work;
        for (Instruction &i : instructions(f)) {
            work.push_back(&i);
        }
        bool changed = false;
        for (Instruction *i : work) {
            IRBuilder<> b(i);
            Value *out = nullptr;
            if (auto *bo = dyn_cast<BinaryOperator>(i)) {
                if (!bo->getType()->isFloatTy()) {
                    continue;
                }
                const char *name = nullptr;
                switch (bo->getOpcode()) {
                    case Instruction::FAdd: name = "sins_c28x_add"; break;
                    case Instruction::FSub: name = "sins_c28x_sub"; break;
                    case Instruction::FMul: name = "sins_c28x_mul"; break;
                    case Instruction::FDiv: name = "sins_c28x_div"; break;
                    default: break;
                }
                if (name == nullptr) {
                    continue;
                }
                out = b.CreateCall(callee(name, fl, {fl, fl}), {bo->getOperand(0), bo->getOperand(1)});
            } else if (i->getOpcode() == Instruction::FNeg && i->getType()->isFloatTy()) {
                out = b.CreateCall(callee("sins_c28x_neg", fl, {fl}), {i->getOperand(0)});
            } else if (auto *c = dyn_cast<CastInst>(i)) {
                Value *src = c->getOperand(0);
                Type *st = src->getType();
                Type *dt = c->getType();
                switch (c->getOpcode()) {
                    case Instruction::SIToFP:
                    case Instruction::UIToFP: {
                        if (!dt->isFloatTy()) {
                            continue;
                        }
                        bool sign = c->getOpcode() == Instruction::SIToFP;
                        if (st->getIntegerBitWidth() <= 32) {
                            Value *w = sign ? b.CreateSExt(src, i32) : b.CreateZExt(src, i32);
                            out = b.CreateCall(
                                callee(sign ? "sins_c28x_from_i32" : "sins_c28x_from_u32", fl, {i32}), {w});
                        } else {
                            /* 64-bit: one rounding to nearest, then canonical. */
                            Value *h = sign ? b.CreateSIToFP(src, fl) : b.CreateUIToFP(src, fl);
                            out = b.CreateCall(callee("sins_c28x_from_f64", fl, {db}), {b.CreateFPExt(h, db)});
                        }
                        break;
                    }
                    case Instruction::FPToSI:
                    case Instruction::FPToUI: {
                        if (!st->isFloatTy()) {
                            continue;
                        }
                        bool sign = c->getOpcode() == Instruction::FPToSI;
                        Value *v = b.CreateCall(
                            callee(sign ? "sins_c28x_to_i32" : "sins_c28x_to_u32", i32, {fl}), {src});
                        out = sign ? b.CreateSExtOrTrunc(v, dt) : b.CreateZExtOrTrunc(v, dt);
                        break;
                    }
                    case Instruction::FPTrunc:
                        if (!dt->isFloatTy() || !st->isDoubleTy()) {
                            continue;
                        }
                        out = b.CreateCall(callee("sins_c28x_from_f64", fl, {db}), {src});
                        break;
                    default: continue;
                }
            } else if (auto *call = dyn_cast<CallInst>(i)) {
                Function *fn = call->getCalledFunction();
                unsigned args = 0;
                const char *model = fn != nullptr ? math_model(fn->getName(), &args) : nullptr;
                if (model == nullptr || call->arg_size() != args) {
                    continue;
                }
                Type *rt = call->getType();
                if (!rt->isFloatTy() && !rt->isDoubleTy()) {
                    continue;
                }
                std::vector<Value *> a;
                std::vector<Type *> p;
                for (unsigned k = 0; k < args; k++) {
                    Value *v = call->getArgOperand(k);
                    if (v->getType()->isDoubleTy()) {
                        /* An argument of the firmware is a float widened: the narrowing is exact. */
                        v = b.CreateFPTrunc(v, fl);
                    } else if (!v->getType()->isFloatTy()) {
                        v = nullptr;
                    }
                    if (v == nullptr) {
                        break;
                    }
                    a.push_back(v);
                    p.push_back(fl);
                }
                if (a.size() != args) {
                    continue;
                }
                out = b.CreateCall(callee(model, fl, p), a);
                if (rt->isDoubleTy()) {
                    out = b.CreateFPExt(out, db);
                }
            } else {
                continue;
            }
            i->replaceAllUsesWith(out);
            i->eraseFromParent();
            changed = true;
        }
        return changed;
    }

    /* A definition of a register-file object (TI's DSP2833x_GlobalVariableDefs.c) made a declaration:
       the build's placement defines it. */
    bool declare_register_files(Module &m) {
        bool changed = false;
        for (GlobalVariable &g : m.globals()) {
            if (!g.isDeclaration() && symbols.count(g.getName().str()) != 0) {
                g.setInitializer(nullptr);
                g.setLinkage(GlobalValue::ExternalLinkage);
                g.setSection("");
                g.setComdat(nullptr);
                changed = true;
            }
        }
        return changed;
    }

    /* Each vector-table image this module defines tells the runtime where it is, at load time. */
    static bool register_images(Module &m, const RegisterPointers &reg) {
        std::vector<GlobalVariable *> defined;
        for (const GlobalVariable *g : reg.images) {
            if (!g->isDeclaration()) {
                defined.push_back(const_cast<GlobalVariable *>(g));
            }
        }
        if (defined.empty()) {
            return false;
        }
        LLVMContext &ctx = m.getContext();
        Type *i8p = Type::getInt8PtrTy(ctx);
        Type *i64 = Type::getInt64Ty(ctx);
        FunctionCallee image = m.getOrInsertFunction("sins_fw_vector_image", Type::getVoidTy(ctx), i8p, i64);
        Function *ctor = Function::Create(FunctionType::get(Type::getVoidTy(ctx), false), GlobalValue::InternalLinkage,
                                          "sins_fw_vector_images", &m);
        IRBuilder<> b(BasicBlock::Create(ctx, "", ctor));
        for (GlobalVariable *g : defined) {
            uint64_t bytes = m.getDataLayout().getTypeAllocSize(g->getValueType());
            b.CreateCall(image, {ConstantExpr::getPointerCast(g, i8p), ConstantInt::get(i64, bytes)});
        }
        b.CreateRetVoid();
        appendToGlobalCtors(m, ctor, 0);
        return true;
    }

    PreservedAnalyses run(Module &m, ModuleAnalysisManager &) {
        bool changed = map_raw_addresses(m);
        changed |= declare_register_files(m);
        RegisterPointers reg(m, symbols);
        changed |= register_images(m, reg);
        for (Function &f : m) {
            if (f.isDeclaration()) {
                continue;
            }
            changed |= instrument_accesses(f, m, reg);
            if (c28x_float) {
                changed |= instrument_floats(f, m);
            }
        }
        return changed ? PreservedAnalyses::none() : PreservedAnalyses::all();
    }
    static bool isRequired() { return true; }
};


/* The C28x cycles of each basic block ($SINS_FW_PASS_COSTS: `key=cycles,...`, written by the build
   from the profile's cost table, c28x-costs.toml [instructions], [float], [iq]: sins_fw.firmware_build
   .block_costs). Run at the end of the optimisation pipeline, it prices each block of the optimised
   IR instruction by instruction and puts at the block's first insertion point one call
   `sins_fw_block(cycles, &counter)` (`sins_fw_enter` at a function's entry block, which also counts the
   call): the runtime adds the cycles to the time due and to `counter`, the function's own ("self") cycles, which the runtime lists by function name (sins_fw_function_cycles).
   Before each return it calls `sins_fw_leave(&counter)`: the function's inclusive cycles. In a block
   with register accesses the first call charges the instructions up to the first access, and a
   `sins_fw_block` after each access the instructions after it (an access is timed after the code
   before it, as on the target).
   An empty endless loop (`for (;;) {}`: a block that only branches to itself) calls
   `sins_fw_idle(cycles)` instead: the runtime moves time to the next interrupt in whole passes.
   Without $SINS_FW_PASS_COSTS the pass prices nothing (a build of another tool). */
std::map<std::string, unsigned> costs_from_env() {
    std::map<std::string, unsigned> out;
    const char *env = std::getenv("SINS_FW_PASS_COSTS");
    if (env == nullptr) {
        return out;
    }
    std::string s(env);
    size_t start = 0;
    while (start < s.size()) {
        size_t comma = s.find(',', start);
        if (comma == std::string::npos) {
            comma = s.size();
        }
        std::string item = s.substr(start, comma - start);
        size_t eq = item.find('=');
        if (eq != std::string::npos) {
            out[item.substr(0, eq)] = static_cast<unsigned>(std::strtoul(item.c_str() + eq + 1, nullptr, 10));
        }
        start = comma + 1;
    }
    return out;
}

struct SinsFwCyclePass : PassInfoMixin<SinsFwCyclePass> {
    std::map<std::string, unsigned> costs = costs_from_env();

    unsigned price(const std::string &key) const {
        auto it = costs.find(key);
        return it == costs.end() ? 0 : it->second;
    }

    /* The price of a call by its callee's name: the runtime's register accesses (their cycles are the
       runtime's: [io] peripheral_read/peripheral_write), the c28x-f32 backend's operations, IQmath's,
       the math library's (host float mode), or a call of the firmware's own (LCR; the callee's blocks
       and return price themselves). */
    unsigned call_price(const CallBase &call) const {
        const Function *fn = call.getCalledFunction();
        StringRef name = fn != nullptr ? fn->getName() : StringRef();
        if (fn != nullptr && fn->isIntrinsic()) {
            Intrinsic::ID id = fn->getIntrinsicID();
            if (id == Intrinsic::memcpy || id == Intrinsic::memmove || id == Intrinsic::memset) {
                /* RPT #n || PREAD/MOV: one word a cycle after the setup. */
                if (auto *len = dyn_cast<ConstantInt>(call.getArgOperand(2))) {
                    return price("block_copy_setup") + static_cast<unsigned>((len->getZExtValue() + 1) / 2);
                }
                return price("block_copy_setup") + price("call");
            }
            if (id == Intrinsic::fabs) return price("float.abs");
            if (id == Intrinsic::sqrt) return price("float.sqrt");
            if (id == Intrinsic::sin) return price("float.sin");
            if (id == Intrinsic::cos) return price("float.cos");
            if (id == Intrinsic::fmuladd || id == Intrinsic::fma) return price("float.mul") + price("float.add");
            if (id == Intrinsic::smax || id == Intrinsic::smin || id == Intrinsic::umax || id == Intrinsic::umin ||
                id == Intrinsic::abs) {
                return 2 * price("int");
            }
            return 0; /* debug info, lifetimes, assumptions: no instruction */
        }
        if (name.startswith("sins_fw_ld") || name.startswith("sins_fw_st") || name == "sins_fw_ptr") {
            return 0;
        }
        if (name == "sins_fw_memcpy" || name == "sins_fw_memset") {
            /* A block copy the build's first pass routed through the runtime: priced as the memcpy. */
            if (auto *len = dyn_cast<ConstantInt>(call.getArgOperand(2))) {
                return price("block_copy_setup") + static_cast<unsigned>((len->getZExtValue() + 1) / 2);
            }
            return price("block_copy_setup") + price("call");
        }
        static const struct {
            const char *prefix;
            const char *key;
        } table[] = {
            {"sins_c28x_add", "float.add"}, {"sins_c28x_sub", "float.add"}, {"sins_c28x_mul", "float.mul"},
            {"sins_c28x_div", "float.div"}, {"sins_c28x_neg", "float.neg"}, {"sins_c28x_abs", "float.abs"},
            {"sins_c28x_sqrt", "float.sqrt"}, {"sins_c28x_sin", "float.sin"}, {"sins_c28x_cos", "float.cos"},
            {"sins_c28x_atan2", "float.atan2"}, {"sins_c28x_atan", "float.atan"}, {"sins_c28x_asin", "float.asin"},
            {"sins_c28x_acos", "float.asin"}, {"sins_c28x_from_", "float.int_to_float"},
            {"sins_c28x_to_", "float.float_to_int"}, {"sins_iq_mpy_i32", "iq.mul_i32"}, {"sins_iq_mpy", "iq.mul"},
            {"sins_iq_rmpy", "iq.mul"}, {"sins_iq_rsmpy", "iq.mul"}, {"sins_iq_div", "iq.div"},
            {"sins_iq_isqrt", "iq.sqrt"}, {"sins_iq_sqrt", "iq.sqrt"}, {"sins_iq_sin", "iq.sin"},
            {"sins_iq_cos", "iq.cos"}, {"sins_iq_atan2", "iq.atan2"}, {"sins_iq_atan", "iq.atan"},
            {"sins_iq_asin", "iq.asin"}, {"sins_iq_abs", "iq.abs"}, {"sins_iq_to_q", "iq.requantise"},
            {"sins_iq_to_f32", "float.int_to_float"}, {"sins_iq_from_f64", "iq.constant"},
            {"sqrtf", "float.sqrt"}, {"sqrt", "float.sqrt"}, {"sinf", "float.sin"}, {"sin", "float.sin"},
            {"cosf", "float.cos"}, {"cos", "float.cos"}, {"atan2f", "float.atan2"}, {"atan2", "float.atan2"},
            {"atanf", "float.atan"}, {"atan", "float.atan"}, {"asinf", "float.asin"}, {"asin", "float.asin"},
            {"acosf", "float.asin"}, {"acos", "float.asin"}, {"fabsf", "float.abs"}, {"fabs", "float.abs"},
        };
        /* A division by a constant power of two is a multiplication by its exact inverse: cl2000
           -O2 emits MPYF32 for it (the result is the same to the bit), as clang does for a host
           float; the C28x mode's call blocks that, so it is priced as the multiplication. */
        if (name == "sins_c28x_div" && call.arg_size() == 2 && exact_inverse(call.getArgOperand(1))) {
            return price("float.mul");
        }
        for (const auto &e : table) {
            size_t n = std::strlen(e.prefix);
            bool prefix = e.prefix[n - 1] == '_';
            if (prefix ? name.startswith(e.prefix) : name == e.prefix) {
                return price(e.key);
            }
        }
        /* A call of the firmware's own or of a library: LCR and an argument move per argument. */
        return price("call") + price("int") * static_cast<unsigned>(call.arg_size());
    }

    /* A floating-point constant (or one converted from one) whose inverse is exact: ±2^k. */
    static bool exact_inverse(Value *v) {
        if (auto *c = dyn_cast<ConstantExpr>(v)) {
            if (c->isCast()) {
                v = c->getOperand(0);
            }
        }
        auto *f = dyn_cast<ConstantFP>(v);
        return f != nullptr && f->getValueAPF().getExactInverse(nullptr);
    }

    /* A call of the runtime's register access (the register's cycles are the runtime's). */
    static bool is_register_access(const Instruction &i) {
        const auto *call = dyn_cast<CallBase>(&i);
        const Function *fn = call != nullptr ? call->getCalledFunction() : nullptr;
        return fn != nullptr && (fn->getName().startswith("sins_fw_ld") || fn->getName().startswith("sins_fw_st"));
    }

    unsigned load_store_price(Type *t, bool store, const DataLayout &dl) const {
        /* A float or double value: its MOV32 to or from an FPU register is the operand move the cost
           table's float prices include (c28x-costs.toml: one per operation), not priced twice. */
        if (t->isFloatingPointTy()) {
            return 0;
        }
        uint64_t bits = t->isSized() ? dl.getTypeSizeInBits(t).getFixedSize() : 32;
        uint64_t words = bits <= 32 ? 1 : (bits + 31) / 32; /* MOV / MOVL: 16 or 32 bits a cycle */
        return static_cast<unsigned>(words) * (store ? price("store") : price("load") + price("data_wait"));
    }

    unsigned instruction_price(Instruction &i, const DataLayout &dl) const {
        if (auto *call = dyn_cast<CallBase>(&i)) {
            return call_price(*call);
        }
        if (auto *bo = dyn_cast<BinaryOperator>(&i)) {
            Type *t = bo->getType();
            /* The host's 64-bit integers are its pointer-width indices and `long`, 32 bits on the C28x
               (an index of a 16-bit `int`, a 22/32-bit XAR address, a 32-bit `long`): priced as one
               32-bit operation (ADDL, CMPL, ...). A multiplication or division of 64 bits keeps the
               RTS price (`long long`). */
            bool wide = t->isIntegerTy() && t->getIntegerBitWidth() > 32;
            switch (bo->getOpcode()) {
                case Instruction::FAdd:
                case Instruction::FSub: return price("float.add");
                case Instruction::FMul: return price("float.mul");
                case Instruction::FDiv:
                    return exact_inverse(bo->getOperand(1)) ? price("float.mul") : price("float.div");
                case Instruction::FRem: return price("float.div") + price("call");
                case Instruction::Mul: return wide ? price("mul64") : price("mul");
                case Instruction::SDiv:
                case Instruction::UDiv:
                case Instruction::SRem:
                case Instruction::URem: return wide ? price("div64") : price("div");
                default: return price("int");
            }
        }
        switch (i.getOpcode()) {
            case Instruction::FNeg: return price("float.neg");
            case Instruction::FCmp: return price("float.compare");
            case Instruction::ICmp: return price("int");
            case Instruction::Select: return price("select");
            case Instruction::SIToFP:
            case Instruction::UIToFP: return price("float.int_to_float");
            case Instruction::FPToSI:
            case Instruction::FPToUI: return price("float.float_to_int");
            case Instruction::SExt:
            case Instruction::ZExt: return price("int");
            case Instruction::GetElementPtr:
                return cast<GetElementPtrInst>(i).hasAllConstantIndices() ? 0 : price("int");
            case Instruction::Load: return load_store_price(i.getType(), false, dl);
            case Instruction::Store:
                return load_store_price(cast<StoreInst>(i).getValueOperand()->getType(), true, dl);
            case Instruction::Br: {
                /* An unconditional branch to the block laid out next is no instruction: the code
                   falls through. */
                auto &br = cast<BranchInst>(i);
                if (br.isConditional()) {
                    return price("cond_branch");
                }
                BasicBlock *next = i.getParent()->getNextNode();
                return br.getSuccessor(0) == next ? 0 : price("branch");
            }
            case Instruction::Switch:
                return price("cond_branch") * static_cast<unsigned>(cast<SwitchInst>(i).getNumCases()) / 2 +
                       price("cond_branch");
            case Instruction::IndirectBr: return price("branch");
            case Instruction::Ret: return price("ret");
            default: return 0; /* phi, casts that are no instruction, alloca, unreachable */
        }
    }

    PreservedAnalyses run(Module &m, ModuleAnalysisManager &) {
        if (costs.empty()) {
            return PreservedAnalyses::all();
        }
        LLVMContext &ctx = m.getContext();
        const DataLayout &dl = m.getDataLayout();
        Type *i32 = Type::getInt32Ty(ctx);
        Type *i64 = Type::getInt64Ty(ctx);
        Type *i8p = Type::getInt8PtrTy(ctx);
        FunctionCallee block = m.getOrInsertFunction("sins_fw_block", Type::getVoidTy(ctx), i32, i8p);
        FunctionCallee enter = m.getOrInsertFunction("sins_fw_enter", Type::getVoidTy(ctx), i32, i8p);
        FunctionCallee idle = m.getOrInsertFunction("sins_fw_idle", Type::getVoidTy(ctx), i32);
        FunctionCallee leave = m.getOrInsertFunction("sins_fw_leave", Type::getVoidTy(ctx), i8p);
        /* The functions the sources place in section ramfuncs (`#pragma CODE_SECTION(f, "ramfuncs")`,
           found by the build): the runtime checks at their entry that the section was copied to RAM. */
        std::set<std::string> ramfuncs;
        if (const char *env = std::getenv("SINS_FW_PASS_RAMFUNCS")) {
            std::string list = env;
            size_t at = 0;
            while (at <= list.size()) {
                size_t comma = list.find(',', at);
                std::string name = list.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
                if (!name.empty()) {
                    ramfuncs.insert(name);
                }
                if (comma == std::string::npos) {
                    break;
                }
                at = comma + 1;
            }
        }
        FunctionCallee ramfunc = m.getOrInsertFunction("sins_fw_ramfunc", Type::getVoidTy(ctx), i8p);
        /* The functions' counters, and a table {name, counter} in the section the runtime walks. */
        StructType *entry = StructType::get(i8p, i8p);
        std::vector<Function *> fns;
        for (Function &f : m) {
            /* (Not the first pass's constructor that registers the vector-table images.) */
            if (!f.isDeclaration() && f.getName() != "sins_fw_vector_images") {
                fns.push_back(&f);
            }
        }
        for (Function *f : fns) {
            /* {self cycles, calls, inclusive cycles, frames running}: the runtime's FunctionRow. */
            auto *counter = new GlobalVariable(m, ArrayType::get(i64, 4), false, GlobalValue::PrivateLinkage,
                                               ConstantAggregateZero::get(ArrayType::get(i64, 4)),
                                               "sins_fw_cycles." + f->getName());
            Constant *name = ConstantExpr::getPointerCast(
                IRBuilder<>(ctx).CreateGlobalStringPtr(f->getName(), "sins_fw_name." + f->getName(), 0, &m), i8p);
            auto *row = new GlobalVariable(m, entry, true, GlobalValue::PrivateLinkage,
                                           ConstantStruct::get(entry, {name, ConstantExpr::getPointerCast(counter, i8p)}),
                                           "sins_fw_fn." + f->getName());
            row->setSection("sins_fw_functions");
            row->setAlignment(Align(8));
            appendToUsed(m, {row});
            Constant *calls = ConstantExpr::getPointerCast(counter, i8p);
            for (BasicBlock &bb : *f) {
                /* A register access (the runtime's sins_fw_ldN/stN) is timed after the instructions
                   before it only: the block's charge at its start runs up to its first access, and each
                   access is followed by the charge of the instructions after it, up to the next. (A
                   poll's status read comes before its test and branch, as on the C28x; charged whole
                   at the block's start, the read would come after them.) */
                uint64_t cycles = 0;
                std::vector<std::pair<Instruction *, uint64_t>> after_access;
                for (Instruction &i : bb) {
                    uint64_t p = instruction_price(i, dl);
                    if (after_access.empty()) {
                        cycles += p;
                    } else {
                        after_access.back().second += p;
                    }
                    if (is_register_access(i)) {
                        after_access.emplace_back(&i, 0);
                    }
                }
                for (const auto &access : after_access) {
                    uint64_t rest = access.second;
                    if (rest > 0) {
                        IRBuilder<>(access.first->getNextNode())
                            .CreateCall(block, {ConstantInt::get(i32, rest > 0xFFFFFFFFu ? 0xFFFFFFFFu : rest), calls});
                    }
                }
                auto *br = dyn_cast<BranchInst>(bb.getTerminator());
                bool self_loop = br != nullptr && br->isUnconditional() && br->getSuccessor(0) == &bb &&
                                 &bb.front() == br;
                IRBuilder<> b(&*bb.getFirstInsertionPt());
                Value *c = ConstantInt::get(i32, cycles > 0xFFFFFFFFu ? 0xFFFFFFFFu : cycles);
                if (self_loop) {
                    b.CreateCall(idle, {c});
                } else {
                    /* The entry block also counts the call (the counter's second word). */
                    b.CreateCall(&bb == &f->getEntryBlock() ? enter : block, {c, calls});
                    if (&bb == &f->getEntryBlock() && ramfuncs.count(f->getName().str()) != 0) {
                        b.CreateCall(ramfunc, {b.CreateGlobalStringPtr(f->getName(), "sins_fw_ramfunc." + f->getName())});
                    }
                }
                /* A return ends the function's frame: its inclusive cycles (sins_fw_leave). */
                if (isa<ReturnInst>(bb.getTerminator())) {
                    IRBuilder<>(bb.getTerminator()).CreateCall(leave, {calls});
                }
            }
        }
        return PreservedAnalyses::none();
    }
    static bool isRequired() { return true; }
};

}  // namespace

extern "C" LLVM_ATTRIBUTE_WEAK PassPluginLibraryInfo llvmGetPassPluginInfo() {
    return {LLVM_PLUGIN_API_VERSION, "sins-fw", "1", [](PassBuilder &pb) {
                pb.registerPipelineStartEPCallback(
                    [](ModulePassManager &mpm, OptimizationLevel) { mpm.addPass(SinsFwPass()); });
                pb.registerOptimizerLastEPCallback(
                    [](ModulePassManager &mpm, OptimizationLevel) { mpm.addPass(SinsFwCyclePass()); });
            }};
}
