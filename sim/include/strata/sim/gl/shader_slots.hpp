#pragma once
// The binding slots of sim/shaders, declared once: the GL backend compiles its kernels with this
// table as #defines (GLSL writes `layout(std430, binding = SLOT_STATE_IN)`) and binds its buffers
// through it; a GPU test checks every kernel's blocks against it (docs/architecture.md, "The GL
// layer"). Which buffer is which is in sim/src/gl/gl_solver.cpp.

#include <vector>

#include <strata/gl/bindings.hpp>

namespace strata::sim::slots {

using gl::ResourceKind;
constexpr ResourceKind kBuf = ResourceKind::kStorageBuffer;

inline constexpr gl::Binding kParams{"SLOT_PARAMS", kBuf, 0, "SimParamsBlock"};        ///< GpuSimParams
inline constexpr gl::Binding kMaterials{"SLOT_MATERIALS", kBuf, 1, "Materials"};       ///< GpuMaterial per layer
inline constexpr gl::Binding kRowDx{"SLOT_ROW_DX", kBuf, 2, "RowDxBlock"};             ///< cell size east-west per row
inline constexpr gl::Binding kBase{"SLOT_BASE", kBuf, 3, "Base"};                      ///< non-erodible base
inline constexpr gl::Binding kBed{"SLOT_BED", kBuf, 4, "Bed"};                         ///< base + layers
inline constexpr gl::Binding kLayers{"SLOT_LAYERS", kBuf, 5, "Layers"};                ///< thicknesses, layer-major
inline constexpr gl::Binding kStateIn{"SLOT_STATE_IN", kBuf, 6, "StateIn"};            ///< h, s, hu, hv now
inline constexpr gl::Binding kStateOut{"SLOT_STATE_OUT", kBuf, 7, "StateOut"};         ///< h, s, hu, hv next
inline constexpr gl::Binding kStage{"SLOT_STAGE", kBuf, 8, "Stage"};                   ///< flood mode's predictor
inline constexpr gl::Binding kFlux{"SLOT_FLUX", kBuf, 9, "Flux"};                      ///< pipe outflows
inline constexpr gl::Binding kFaceX{"SLOT_FACE_X", kBuf, 10, "FaceX"};                 ///< flood mode x faces
inline constexpr gl::Binding kFaceY{"SLOT_FACE_Y", kBuf, 11, "FaceY"};                 ///< flood mode y faces
inline constexpr gl::Binding kTilt{"SLOT_TILT", kBuf, 12, "Tilt"};                     ///< sin(bed tilt)
inline constexpr gl::Binding kAccum{"SLOT_ACCUM", kBuf, 13, "AccumBlock"};             ///< compensated budget sums
inline constexpr gl::Binding kRain{"SLOT_RAIN", kBuf, 14, "Rain"};                     ///< rain raster
inline constexpr gl::Binding kThermal{"SLOT_THERMAL", kBuf, 15, "Thermal"};            ///< material shed per face
inline constexpr gl::Binding kSources{"SLOT_SOURCES", kBuf, 16, "Sources"};            ///< this step's SourceEntry list
inline constexpr gl::Binding kMaxSpeed{"SLOT_MAX_SPEED", kBuf, 17, "MaxSpeed"};        ///< the wave speed reduction
inline constexpr gl::Binding kFluxDiag{"SLOT_FLUX_DIAG", kBuf, 18, "FluxDiag"};        ///< diagonal pipe outflows
inline constexpr gl::Binding kFloodStats{"SLOT_FLOOD_STATS", kBuf, 19, "FloodStats"};  ///< per-cell flood maxima
inline constexpr gl::Binding kFvLimit{"SLOT_FV_LIMIT", kBuf, 20, "Limit"};             ///< W25 outflow limits
inline constexpr gl::Binding kLevels{"SLOT_LEVELS", kBuf, 21, "Levels"};               ///< this step's LevelEntry list
inline constexpr gl::Binding kCopyGrid{"SLOT_COPY_GRID", kBuf, 22, "Grid"};            ///< copy_rect: a per-cell buffer
inline constexpr gl::Binding kCopyPacked{"SLOT_COPY_PACKED", kBuf, 23, "Rect"};  ///< copy_rect: the packed rectangle
inline constexpr gl::Binding kScour{"SLOT_SCOUR", kBuf, 24, "Scour"};            ///< the step's toe scour (E8)
inline constexpr gl::Binding kManning{"SLOT_MANNING", kBuf, 25, "Manning"};      ///< n^2 per cell; < 0: P.manningN
inline constexpr gl::Binding kInfiltration{"SLOT_INFILTRATION", kBuf, 26,
                                           "Infiltration"};  ///< (Ks, psi dtheta) per cell

inline constexpr gl::Binding kClock{"SLOT_CLOCK", kBuf, 27, "ClockBlock"};  ///< W35: GpuClock, the GPU's clock
inline constexpr gl::Binding kSeries{"SLOT_SERIES", kBuf, 28, "Series"};    ///< W35: the sources' samples (t, q)
inline constexpr gl::Binding kTerms{"SLOT_TERMS", kBuf, 29, "Terms"};       ///< W35: GpuTerm per source and entry

inline constexpr gl::Binding kAll[] = {
    kParams,  kMaterials, kRowDx,    kBase,       kBed,   kLayers,  kStateIn,      kStateOut, kStage,    kFlux,
    kFaceX,   kFaceY,     kTilt,     kAccum,      kRain,  kThermal, kSources,      kMaxSpeed, kFluxDiag, kFloodStats,
    kFvLimit, kLevels,    kCopyGrid, kCopyPacked, kScour, kManning, kInfiltration, kClock,    kSeries,   kTerms};

/// What the kernels compile with: this table's slots and the accumulators' layout as
/// ACCUM_PER_CELL, ACCUM_OUTFLOW, ... (sim::AccumOffset).
std::vector<gl::ShaderDefine> kernelDefines();

}  // namespace strata::sim::slots
