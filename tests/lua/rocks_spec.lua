-- rocks_spec.lua — rock piles on material stacks (Peytavie et al. 2009,
-- section 5): outcrop.layers.rocks gives a block tile of rocks;
-- s:rocks places them only where a rocks layer is, within its depth, as
-- part of a node (the rocks above the ground) or as an instance list;
-- the same tile for the same seed; errors with the script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "rocks_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local T = 0.5

describe("outcrop.layers.rocks", function()
  local tile = oc.layers.rocks{size = 6, radius = 1.5, seed = 5}

  it("makes a tile of rocks, the same for the same seed", function()
    local n = tile:count()
    assert.is_true(n > 30 and n < 80, n)
    local st = tile:stats()
    assert.are.equal(n, st.blocks)
    assert.are.equal(n, st.points)
    local again = oc.layers.rocks{size = 6, radius = 1.5, seed = 5}
    assert.are.equal(n, again:count())
    local p = {1.1, 2.2, 3.3}
    assert.are.equal(tile:node():eval(p), again:node():eval(p))
  end)

  it("places rocks only in the rocks layer, within its depth", function()
    -- rocks 3 m thick on 2 m of bedrock over x < 8, bedrock alone beyond
    local s = oc.layers.new{size = {32, 16}, cell = 0.5,
                            layers = {{"bedrock", 2}}}
    for j = 1, 16 do
      for i = 1, 16 do s:set(i, j, {{"bedrock", 2}, {"rocks", 3}}) end
    end
    local node, info = s:rocks(tile, {list = true})
    assert.is_true(info.instances > 10, info.instances)
    assert.are.equal(info.instances, #info.list)
    assert.are.equal(2 * info.reach, info.depth)
    for _, r in ipairs(info.list) do
      assert.is_true(r.block >= 1 and r.block <= tile:count())
      assert.are.equal(3, #r.offset)
    end
    -- above the ground at the rocks' height: rocks over the rocks layer,
    -- none farther from it than a rock's reach and its field's width
    local inside = {0, 0}
    for y = 0.25, 7.5, 0.5 do
      for x = 0.25, 15.5, 0.5 do
        if node:eval{x, y, 3.5} > T then
          local side = x < 7.75 and 1 or x > 7.75 + info.reach + 0.75 and 2
          if side then inside[side] = inside[side] + 1 end
        end
      end
    end
    assert.is_true(inside[1] > 30, inside[1])
    assert.are.equal(0, inside[2])
    -- a shallower depth keeps fewer rocks; the ground is the default's
    local _, few = s:rocks(tile, {depth = 0.5})
    assert.is_true(few.instances < info.instances)
    local ground = s:field{materials = {"bedrock"}}
    local n2 = s:rocks(tile, {ground = ground})
    assert.are.equal(node:eval{12, 4, 1.9}, n2:eval{12, 4, 1.9})
  end)

  it("reports bad input with the script line", function()
    local s = oc.layers.new{size = {4, 4}}
    check(function() oc.layers.rocks{radius = -1} end, "outcrop.layers.rocks", "'radius'")
    check(function() oc.layers.rocks{size = 2, radius = 1} end, "outcrop.layers.rocks", "'size'")
    check(function() oc.layers.rocks{erosion = 0.6} end, "outcrop.layers.rocks", "'erosion'")
    check(function() oc.layers.rocks{contacts = 0} end, "outcrop.layers.rocks", "'contacts'")
    check(function() oc.layers.rocks{colour = 1} end, "outcrop.layers.rocks", "colour")
    check(function() s:rocks(42) end, "layers:rocks", "argument #2")
    check(function() s:rocks(tile, {depth = -1}) end, "layers:rocks", "'depth'")
    check(function() s:rocks(tile, {ground = 3}) end, "layers:rocks", "'ground'")
  end)
end)
