// Access to a sort's keys in either layout (passes/key_buffers.h): 32-bit words when the sort's keys
// fit 32 bits, else 64-bit. The including shader declares the specialization constant WIDE_KEYS;
// the branch folds away when the pipeline is specialized.
uint64_t load_key(uint64_t keys, uint i) {
  if (WIDE_KEYS) return Uint64Array(keys).v[i];
  return uint64_t(UintArray(keys).v[i]);
}

void store_key(uint64_t keys, uint i, uint64_t key) {
  if (WIDE_KEYS)
    Uint64Array(keys).v[i] = key;
  else
    UintArray(keys).v[i] = uint(key);
}
