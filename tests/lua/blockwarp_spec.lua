-- blockwarp_spec.lua — outcrop.relief_warp (Paris et al. 2020, section
-- 4.2), the replication's inset, tile:meshes, tile:save and
-- outcrop.blocks.load: values against formulas, round trips, and every
-- error with its script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "blockwarp_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local B = oc.blocks

-- a small tile: 8 m, r = 0.5 (about 3 000 points), fast
local function small(seed)
  return B.tile{size = 8, radius = 0.5, disc_radius = {2, 3}, spacing = 1,
                seed = seed or 4}
end

describe("outcrop.relief_warp", function()
  local ball = oc.sphere{center = {0, 0, 0}, radius = 1, falloff = 0.5}

  it("states its Lipschitz bound L (1 + L_d + 2 (1 + 2 sqrt 3) A / h)", function()
    local w = oc.relief_warp(ball, {relief = {wavelength = 0.4, octaves = 3}, amplitude = 0.06})
    assert.are.equal("relief_warp", w:kind())
    local L = ball:lipschitz()
    -- L_d = 2 A Lip(t) / (t_max wavelength): read back from the bound
    -- with a second step, the only term that depends on it
    local w2 = oc.relief_warp(ball, {relief = {wavelength = 0.4, octaves = 3}, amplitude = 0.06, step = 0.48})
    local k = 2 * (1 + 2 * math.sqrt(3)) * 0.06
    R.close(w:lipschitz() - w2:lipschitz(), L * (k / 0.24 - k / 0.48), 1e-9)
    -- random pairs stay under the bound
    local worst = 0
    for i = 1, 400 do
      local p = {math.sin(i) * 1.4, math.cos(i * 1.3) * 1.4, math.sin(i * 0.7) * 1.4}
      local q = {p[1] + 1e-3 * math.cos(i), p[2] + 1e-3 * math.sin(i * 2), p[3] + 1e-3}
      local d = R.len(R.sub(p, q))
      worst = math.max(worst, math.abs(w:eval(p) - w:eval(q)) / d)
    end
    assert.is_true(worst <= w:lipschitz(), worst)
    assert.is_true(worst > 0.5 * L, worst)
  end)

  it("is the field itself for amplitude 0, and grows the support by A", function()
    local w = oc.relief_warp(ball, {relief = "turbulence", amplitude = 0})
    for i = 1, 50 do
      local p = {math.sin(i) * 1.5, math.cos(i) * 1.5, (i % 7) / 5 - 0.6}
      assert.are.equal(ball:eval(p), w:eval(p))
    end
    local a = {ball:bounds()}
    local b = {oc.relief_warp(ball, {amplitude = 0.1}):bounds()}
    R.close(b[1], a[1] - 0.1, 1e-9)
    R.close(b[6], a[6] + 0.1, 1e-9)
  end)

  it("names the field in errors", function()
    check(function() oc.relief_warp(ball, {}) end, "outcrop.relief_warp", "'amplitude'")
    check(function() oc.relief_warp(ball, {amplitude = 0.1, relief = "noise"}) end, "outcrop.relief_warp", "'relief' must be \"turbulence\"")
    check(function() oc.relief_warp(ball, {amplitude = 0.1, relief = {kind = "image"}}) end, "outcrop.relief_warp", "'relief.path'")
    check(function() oc.relief_warp(ball, {amplitude = 0.1, relief = {octaves = 0}}) end, "outcrop.relief_warp", "'relief.octaves'")
    check(function() oc.relief_warp(ball, {amplitude = 0.1, relief = {path = "x.png"}}) end, "outcrop.relief_warp", "'relief.path' is for kind = \"image\" only")
    check(function() oc.relief_warp(ball, {amplitude = 0.1, relief = {kind = "image", path = "/nonexistent.png"}}) end, "outcrop.relief_warp", "cannot read '/nonexistent.png'")
    check(function() oc.relief_warp(ball, {amplitude = 0.1, stp = 1}) end, "outcrop.relief_warp", "unknown field 'stp'")
    check(function() oc.relief_warp(3, {amplitude = 0.1}) end, "outcrop.relief_warp", "argument #1")
  end)
end)

describe("outcrop.blocks.replicate inset", function()
  local ter = oc.box{min = {0, 0, 0}, max = {16, 16, 10}, falloff = 1}
  local t = small(4)

  it("sinks the wall where blocks are and keeps the blocks", function()
    local r0 = B.replicate(ter, {tiles = {{tile = t}}, slope = 0.5})
    local ri = B.replicate(ter, {tiles = {{tile = t}}, slope = 0.5, inset = 0.3})
    R.close(ri:lipschitz(), ter:lipschitz() * (1 + 0.3 / 0.5), 1e-9)
    local opened, n = 0, 0
    for y = 1, 15, 0.25 do
      for z = 1, 9, 0.25 do
        local p = {-0.3, y, z}
        local f, f0, fi = ter:eval(p), r0:eval(p), ri:eval(p)
        assert.is_true(fi <= f0)
        if f0 > f then assert.are.equal(f0, fi) end
        if fi < 0.5 then opened = opened + 1 end
        n = n + 1
      end
    end
    assert.is_true(opened > n / 50 and opened < n / 2, opened)
    check(function() B.replicate(ter, {tiles = {{tile = t}}, inset = -1}) end, "outcrop.blocks.replicate", "'inset' must be >= 0")
  end)
end)

describe("tile:meshes, tile:save, outcrop.blocks.load", function()
  local t = small(6)

  it("gives one closed mesh of genus 0 per block", function()
    local ms = t:meshes{cell = 0.15}
    assert.are.equal(t:count(), #ms)
    for i = 1, 3 do
      local nv, nt = ms[i]:counts()
      assert.is_true(nt > 50)
      assert.are.equal(2 * (nv - 2), nt)
      -- its vertices lie on the block's surface f = T
      local x, y, z = ms[i]:vertex(1)
      R.close(t:block(i):eval{x, y, z}, 0.5, 0.02)
    end
    check(function() t:meshes{cell = -1} end, "tile:meshes", "'cell'")
  end)

  it("saves and loads the tile, its field bit for bit", function()
    local dir = R.tmpdir()
    assert.is_true(t:save(dir .. "/t.octile"))
    local l = B.load(dir .. "/t.octile")
    local a, b = t:stats(), l:stats()
    for _, k in ipairs{"points", "fractures", "blocks", "edges", "cut", "thick", "separated"} do
      assert.are.equal(a[k], b[k], k)
    end
    local na, nb = t:node(), l:node()
    for i = 0, 300 do
      local p = {(i * 0.37) % 8, (i * 0.71) % 8, (i * 0.13) % 8}
      assert.are.equal(na:eval(p), nb:eval(p))
    end
    -- an unwritable path: nil and a message
    local ok, msg = t:save(dir .. "/t.octile/x")
    assert.is_nil(ok)
    assert.truthy(msg:find("t.octile/x", 1, true))
    local f = io.open(dir .. "/bad.octile", "wb")
    f:write("OCBTILE\n\1\0\0\0")
    f:close()
    check(function() B.load(dir .. "/bad.octile") end, "outcrop.blocks.load", "is not a valid tile file")
    check(function() B.load(dir .. "/none.octile") end, "outcrop.blocks.load", "cannot read")
    check(function() B.load(3) end, "outcrop.blocks.load", "the path must be a string")
    R.rmdir(dir)
  end)
end)
