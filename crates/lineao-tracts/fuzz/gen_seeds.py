# Writes the fuzz seeds (fuzz/seeds/<target>/): one small valid file per format, made here, never
# copied from ../shared/data. Usage: python3 gen_seeds.py seeds
import struct, zipfile, io, gzip, base64, json, os, sys
root = sys.argv[1]
def put(target, name, data):
    d = os.path.join(root, target); os.makedirs(d, exist_ok=True)
    open(os.path.join(d, name), 'wb').write(data)
pts = [[(0,1,2)], [(3,4,5),(6,7,8)], [(1.5,-2,3),(4,5,6),(7,8,9)]]
# tck (+ gz), tsf
h = b"mrtrix tracks\ncount: 3\ndatatype: Float32LE\nfile: . 64\nEND\n".ljust(64, b"\0")
body = b"".join(b"".join(struct.pack('<3f', *p) for p in s) + struct.pack('<3f', *[float('nan')]*3) for s in pts) + struct.pack('<3f', *[float('inf')]*3)
put('tck', 'simple.tck', h + body); put('tck', 'simple.tck.gz', gzip.compress(h + body))
hb = b"mrtrix tracks\ndatatype: Float64BE\nfile: . 64\nEND\n".ljust(64, b"\0")
put('tck', 'f64be.tck', hb + b"".join(struct.pack('>3d', *p) for s in pts for p in s))
ht = b"mrtrix track scalars\ndatatype: Float32LE\nfile: . 64\nEND\n".ljust(64, b"\0")
put('tsf', 'simple.tsf', ht + struct.pack('<7f', 1, float('nan'), 2, 3, float('nan'), 4, 5))
# trk v2 with 1 scalar and 1 property, LPS
hdr = bytearray(1000); hdr[0:6] = b"TRACK\0"; struct.pack_into('<3h', hdr, 6, 4, 5, 6); struct.pack_into('<3f', hdr, 12, 1, 2, 3)
struct.pack_into('<h', hdr, 36, 1); hdr[38:40] = b"fa"; struct.pack_into('<h', hdr, 238, 1); hdr[240:243] = b"len"
struct.pack_into('<16f', hdr, 440, 1,0,0,0, 0,2,0,0, 0,0,3,0, 0,0,0,1); hdr[948:951] = b"LPS"
struct.pack_into('<iii', hdr, 988, 3, 2, 1000)
body = b"".join(struct.pack('<i', len(s)) + b"".join(struct.pack('<4f', *p, 0.5) for p in s) + struct.pack('<f', len(s)) for s in pts)
put('trk', 'lps.trk', bytes(hdr) + body)
# trx zip
b = io.BytesIO(); z = zipfile.ZipFile(b, 'w', zipfile.ZIP_DEFLATED)
z.writestr('header.json', json.dumps({"VOXEL_TO_RASMM": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "DIMENSIONS": [2,2,2], "NB_VERTICES": 6, "NB_STREAMLINES": 3}))
z.writestr('positions.3.float16', b"".join(struct.pack('<3e', *p) for s in pts for p in s))
z.writestr('offsets.uint32', struct.pack('<3I', 0, 1, 3))
z.writestr('dpv/fa.float32', struct.pack('<6f', *range(6))); z.writestr('dps/len.2.uint8', bytes(6))
z.writestr('groups/g.uint32', struct.pack('<2I', 0, 2)); z.writestr('dpg/g/w.float64', struct.pack('<d', 1))
z.close(); put('trx', 'small.trx', b.getvalue())
# vtk ascii 5.1 and binary old
put('vtk', 'lines51.vtk', b"# vtk DataFile Version 5.1\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 2 0 0\nLINES 3 4\nOFFSETS vtktypeint64\n0 2 4\nCONNECTIVITY vtktypeint64\n0 1 1 2\nPOINT_DATA 3\nSCALARS fa float 1\nLOOKUP_TABLE default\n1 2 3\nCELL_DATA 2\nFIELD f 1\nid 1 2 int\n7 8\n")
put('vtk', 'old_binary.vtk', b"# vtk DataFile Version 3.0\nx\nBINARY\nDATASET POLYDATA\nPOINTS 3 float\n" + struct.pack('>9f', 0,0,0,1,0,0,2,0,0) + b"\nLINES 1 4\n" + struct.pack('>4i', 3, 0, 1, 2) + b"\n")
# vtp ascii + binary zlib
import zlib
def blk(raw):
    c = zlib.compress(raw); return base64.b64encode(struct.pack('<4I', 1, len(raw), len(raw), len(c))).decode() + base64.b64encode(c).decode()
put('vtp', 'ascii.vtp', b'<VTKFile type="PolyData"><PolyData><Piece NumberOfPoints="3" NumberOfLines="1"><Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 2 0 0</DataArray></Points><Lines><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray><DataArray type="Int32" Name="offsets" format="ascii">3</DataArray></Lines></Piece></PolyData></VTKFile>')
put('vtp', 'zlib.vtp', ('<VTKFile type="PolyData" compressor="vtkZLibDataCompressor"><PolyData><Piece><Points><DataArray type="Float32" NumberOfComponents="3" format="binary">%s</DataArray></Points><Lines><DataArray type="Int64" Name="connectivity" format="binary">%s</DataArray><DataArray type="Int64" Name="offsets" format="binary">%s</DataArray></Lines></Piece></PolyData></VTKFile>' % (blk(struct.pack('<9f',0,0,0,1,0,0,2,0,0)), blk(struct.pack('<3q',0,1,2)), blk(struct.pack('<q',3)))).encode())
# tt: MAT v4 records, gzipped
def rec(name, ty, rows, cols, data):
    n = name.encode() + b"\0"; return struct.pack('<5i', ty, rows, cols, 0, len(n)) + n + data
track = struct.pack('<I3i', 9, 32, 64, 96) + bytes([1, 2, 3, 0xFF, 0xFE, 0xFD])
mat = rec('dimension', 20, 1, 3, struct.pack('<3i', 10, 10, 10)) + rec('voxel_size', 10, 1, 3, struct.pack('<3f', 1, 1, 1)) \
    + rec('trans_to_mni', 10, 1, 16, struct.pack('<16f', -1,0,0,78, 0,-1,0,76, 0,0,1,-50, 0,0,0,1)) + rec('track', 50, len(track), 1, track) \
    + rec('cluster', 40, 1, 1, struct.pack('<H', 0))
put('tt', 'tiny.tt.gz', gzip.compress(mat))
# gltf with an embedded buffer: LINE_STRIP and LINES
buf = struct.pack('<9f', 0,0,0,1,0,0,1,1,0) + struct.pack('<4H', 0, 1, 1, 2)
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "translation": [1, 2, 3]}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 3}, {"attributes": {"POSITION": 0}, "indices": 1, "mode": 1}]}],
     "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
     "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 8}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
                   {"bufferView": 1, "componentType": 5123, "count": 4, "type": "SCALAR"}]}
put('gltf', 'lines.gltf', json.dumps(g).encode())
put('obj', 'lines.obj', b"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\nl -1 -3\nf 1 2 3\n")
# NIfTI volumes (the `nifti` target): 2 x 3 x 2 voxels, NIfTI-1 float32 with an sform and int16
# scaled with a qform, NIfTI-2 little- and big-endian (+ gz)
def nii1(dtype, code, values, qform):
    h = bytearray(348); struct.pack_into('<i', h, 0, 348); struct.pack_into('<8h', h, 40, 3, 2, 3, 2, 1, 1, 1, 1)
    struct.pack_into('<2h', h, 70, code, struct.calcsize(dtype) * 8); struct.pack_into('<8f', h, 76, -1, 2, 2, 2, 1, 1, 1, 1)
    struct.pack_into('<3f', h, 108, 352, 0.5, 1)
    if qform: struct.pack_into('<h', h, 252, 1); struct.pack_into('<6f', h, 256, 0, 0.7071068, 0, 10, -20, 30)
    else: struct.pack_into('<h', h, 254, 2); struct.pack_into('<12f', h, 280, -2,0,0,4, 0,2,0,-6, 0,0,2,8)
    h[344:348] = b"n+1\0"
    return bytes(h) + bytes(4) + struct.pack('<%d%s' % (len(values), dtype), *values)
put('nifti', 'sform_f32.nii', nii1('f', 16, [float(v) for v in range(12)], False))
put('nifti', 'qform_i16.nii', nii1('h', 4, list(range(-6, 6)), True))
def nii2(order):
    h = bytearray(540); struct.pack_into(order + 'i', h, 0, 540); h[4:12] = b"n+2\0\r\n\x1a\n"
    struct.pack_into(order + '2h', h, 12, 16, 32); struct.pack_into(order + '8q', h, 16, 3, 2, 3, 2, 1, 1, 1, 1)
    struct.pack_into(order + '8d', h, 104, 1, 2, 2, 2, 1, 1, 1, 1); struct.pack_into(order + 'q3d', h, 168, 544, 1, 0, 0)
    struct.pack_into(order + '2i', h, 344, 1, 2); struct.pack_into(order + '6d', h, 352, 0, 0, 0, 1, 2, 3)
    struct.pack_into(order + '12d', h, 400, 2,0,0,4, 0,2,0,-6, 0,0,2,8)
    return bytes(h) + bytes(4) + struct.pack(order + '12f', *range(12))
put('nifti', 'le.nii', nii2('<')); put('nifti', 'be.nii', nii2('>')); put('nifti', 'le.nii.gz', gzip.compress(nii2('<')))
